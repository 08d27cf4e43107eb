//! Getting the program out of a code-generation reply.
//!
//! Rules (nesy's, documented in the README):
//! - A fenced block opens with a line of three or more backticks or tildes (any leading
//!   whitespace, an optional info string whose first word is the language tag) and closes at
//!   the next line holding only a fence of the same character at least as long. A block
//!   that never closes runs to the end of the reply and is marked `terminated: false`.
//! - Candidates are the blocks tagged `python`, `py` or `python3` (any case); if there are
//!   none, the untagged blocks. Blocks tagged with another language (`text`, `json`, `bash`,
//!   ...) are never taken.
//! - Among several candidates the one that calls the most robot API functions wins; a tie
//!   goes to the later block (models put a corrected or complete version after a sketch).
//! - Prose around the blocks is ignored. A reply without any candidate is an error.
//! - Top-level `from X import ...` lines that import only robot API functions (or `*`) from
//!   a module other than `robot` are removed, because the sandbox provides the functions as
//!   globals and has no such module; each removal is recorded. Imports of `robot`, `math`
//!   and `numpy` are kept (the sandbox allows them), and any other import is kept too, so
//!   that the sandbox's static check reports it instead of nesy hiding it.

use serde::{Deserialize, Serialize};

use crate::prompts::api_docs;

/// Where the chosen block was and how it was picked.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct CodeBlock {
    /// 0-based index among all fenced blocks of the reply.
    pub index: usize,
    /// Number of fenced blocks in the reply.
    pub blocks: usize,
    /// Number of candidate blocks (python-tagged, else untagged).
    pub candidates: usize,
    /// The block's language tag, if any.
    pub language: Option<String>,
    /// 1-based line of the opening fence in the reply.
    pub line: usize,
    /// False when the block had no closing fence (a cut-off reply).
    pub terminated: bool,
}

/// An import line removed from the program.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct StrippedImport {
    /// 1-based line within the block where the statement started.
    pub line: usize,
    /// The statement as written (all its lines).
    pub text: String,
    /// Why it was removed.
    pub reason: String,
}

/// The program taken from a reply.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct ExtractedCode {
    /// The program, after import stripping, with a trailing newline.
    pub code: String,
    /// Which block it came from.
    pub block: CodeBlock,
    /// Import statements removed from it.
    pub stripped: Vec<StrippedImport>,
}

/// Why no program could be taken from a reply.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error, Serialize, Deserialize)]
pub enum ExtractError {
    /// No fenced block at all.
    #[error("the reply holds no fenced code block (expected ```python ... ```); it starts {excerpt:?}")]
    NoCodeBlock {
        /// The reply's first characters.
        excerpt: String,
    },
    /// Fenced blocks, but none tagged python and none untagged.
    #[error("the reply's code blocks are tagged {languages:?}, none is python")]
    NoPythonBlock {
        /// The tags found.
        languages: Vec<String>,
    },
    /// The chosen block is empty.
    #[error("the code block opened on line {line} is empty")]
    EmptyBlock {
        /// 1-based line of its fence.
        line: usize,
    },
    /// The chosen block calls no robot function.
    #[error("the code block opened on line {line} calls no robot API function")]
    NoRobotCalls {
        /// 1-based line of its fence.
        line: usize,
    },
}

struct Fenced<'a> {
    line: usize,
    language: Option<String>,
    body: Vec<&'a str>,
    terminated: bool,
}

fn fence_of(line: &str) -> Option<(char, usize, &str)> {
    let t = line.trim_start();
    let c = t.chars().next()?;
    if c != '`' && c != '~' {
        return None;
    }
    let n = t.chars().take_while(|x| *x == c).count();
    (n >= 3).then(|| (c, n, t[n..].trim()))
}

fn fenced_blocks(reply: &str) -> Vec<Fenced<'_>> {
    let lines: Vec<&str> = reply.lines().collect();
    let mut blocks = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let Some((c, n, info)) = fence_of(lines[i]) else {
            i += 1;
            continue;
        };
        // An info string containing the fence character is inline code, not a fence.
        if c == '`' && info.contains('`') {
            i += 1;
            continue;
        }
        let language = info
            .split_whitespace()
            .next()
            .map(|w| w.trim_start_matches('{').trim_start_matches('.').to_string())
            .filter(|w| !w.is_empty());
        let start = i;
        let mut body = Vec::new();
        let mut terminated = false;
        i += 1;
        while i < lines.len() {
            if let Some((c2, n2, rest)) = fence_of(lines[i])
                && c2 == c
                && n2 >= n
                && rest.is_empty()
            {
                terminated = true;
                i += 1;
                break;
            }
            body.push(lines[i]);
            i += 1;
        }
        blocks.push(Fenced {
            line: start + 1,
            language,
            body,
            terminated,
        });
    }
    blocks
}

fn is_python(tag: &str) -> bool {
    matches!(tag.to_ascii_lowercase().as_str(), "python" | "py" | "python3")
}

/// How many robot API calls a program makes (occurrences of `name(`).
pub fn count_api_calls(code: &str) -> usize {
    api_docs::all_functions()
        .map(|name| call_offsets(code, name).count())
        .sum()
}

/// Byte offsets in `text` where `name(` is written as a call: not the tail of a longer name.
pub(crate) fn call_offsets<'a>(text: &'a str, name: &'a str) -> impl Iterator<Item = usize> + 'a {
    text.match_indices(name).map(|(at, _)| at).filter(move |&at| {
        let before = text[..at].chars().next_back();
        let after = text[at + name.len()..].trim_start().starts_with('(');
        after && !before.is_some_and(|c| c.is_alphanumeric() || c == '_')
    })
}

/// Takes the program out of a reply (see the module documentation for the rules).
pub fn extract_code(reply: &str) -> Result<ExtractedCode, ExtractError> {
    let blocks = fenced_blocks(reply);
    if blocks.is_empty() {
        return Err(ExtractError::NoCodeBlock {
            excerpt: reply.trim().chars().take(80).collect(),
        });
    }
    let tagged: Vec<usize> = (0..blocks.len())
        .filter(|&i| blocks[i].language.as_deref().is_some_and(is_python))
        .collect();
    let candidates = if tagged.is_empty() {
        (0..blocks.len())
            .filter(|&i| blocks[i].language.is_none())
            .collect()
    } else {
        tagged
    };
    if candidates.is_empty() {
        return Err(ExtractError::NoPythonBlock {
            languages: blocks.iter().filter_map(|b| b.language.clone()).collect(),
        });
    }
    let text_of = |b: &Fenced<'_>| b.body.join("\n");
    // Most robot calls wins; ties go to the later block.
    let chosen = candidates
        .iter()
        .copied()
        .max_by_key(|&i| (count_api_calls(&text_of(&blocks[i])), i))
        .unwrap_or(candidates[0]);
    let block = &blocks[chosen];
    let info = CodeBlock {
        index: chosen,
        blocks: blocks.len(),
        candidates: candidates.len(),
        language: block.language.clone(),
        line: block.line,
        terminated: block.terminated,
    };
    let body = dedent(&block.body);
    if body.iter().all(|l| l.trim().is_empty()) {
        return Err(ExtractError::EmptyBlock { line: block.line });
    }
    let (kept, stripped) = strip_foreign_api_imports(&body);
    let mut code = kept.join("\n").trim_matches('\n').to_string();
    code.push('\n');
    if count_api_calls(&code) == 0 {
        return Err(ExtractError::NoRobotCalls { line: block.line });
    }
    Ok(ExtractedCode {
        code,
        block: info,
        stripped,
    })
}

/// Removes the indentation common to every non-blank line (a block inside a list item).
fn dedent(lines: &[&str]) -> Vec<String> {
    let indent = lines
        .iter()
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.len() - l.trim_start().len())
        .min()
        .unwrap_or(0);
    lines
        .iter()
        .map(|l| {
            if l.trim().is_empty() {
                String::new()
            } else {
                l[indent.min(l.len() - l.trim_start().len())..]
                    .trim_end()
                    .to_string()
            }
        })
        .collect()
}

const SANDBOX_MODULES: [&str; 3] = ["robot", "math", "numpy"];

fn strip_foreign_api_imports(lines: &[String]) -> (Vec<String>, Vec<StrippedImport>) {
    let mut kept = Vec::with_capacity(lines.len());
    let mut stripped = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let line = &lines[i];
        let statement_end = if line.starts_with("from ") && line.contains(" import ") {
            // A parenthesised list may span several lines.
            let mut end = i;
            if line.contains('(') && !line.contains(')') {
                while end + 1 < lines.len() && !lines[end].contains(')') {
                    end += 1;
                }
            }
            Some(end)
        } else {
            None
        };
        let Some(end) = statement_end else {
            kept.push(line.clone());
            i += 1;
            continue;
        };
        let text = lines[i..=end].join("\n");
        let (module, names) = {
            let rest = &text["from ".len()..];
            let (module, names) = rest.split_once(" import ").unwrap_or((rest, ""));
            let names: Vec<String> = names
                .replace(['(', ')', '\\', '\n'], " ")
                .split(',')
                .map(|n| n.split_whitespace().next().unwrap_or("").to_string())
                .filter(|n| !n.is_empty())
                .collect();
            (module.trim().to_string(), names)
        };
        let all_api = !names.is_empty()
            && names
                .iter()
                .all(|n| n == "*" || api_docs::all_functions().any(|f| f == n));
        if all_api && !SANDBOX_MODULES.contains(&module.as_str()) {
            stripped.push(StrippedImport {
                line: i + 1,
                text,
                reason: format!(
                    "imports robot API functions from `{module}`, which the sandbox does not have; the functions are provided as globals"
                ),
            });
        } else {
            kept.extend(lines[i..=end].iter().cloned());
        }
        i = end + 1;
    }
    (kept, stripped)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_tagged_block_with_prose_around() {
        let reply = "Here is the program:\n\n```python\nmove_gripper_to(\"apple\")\nclose_gripper()\n```\n\nIt grasps the apple.";
        let got = extract_code(reply).unwrap();
        assert_eq!(got.code, "move_gripper_to(\"apple\")\nclose_gripper()\n");
        assert_eq!(got.block.line, 3);
        assert_eq!(got.block.language.as_deref(), Some("python"));
        assert!(got.block.terminated);
        assert!(got.stripped.is_empty());
    }

    #[test]
    fn untagged_and_tilde_fences() {
        let got = extract_code("```\nopen_gripper()\n```").unwrap();
        assert_eq!(got.code, "open_gripper()\n");
        assert_eq!(got.block.language, None);
        let got = extract_code("~~~~ py\nopen_gripper()\n~~~~\n").unwrap();
        assert_eq!(got.block.language.as_deref(), Some("py"));
    }

    #[test]
    fn python_blocks_beat_untagged_and_other_languages() {
        let reply = "```text\nclose_gripper()\nclose_gripper()\n```\n```\nopen_gripper()\nopen_gripper()\n```\n```Python\nmove_parallel(\"up\", 0.1)\n```";
        let got = extract_code(reply).unwrap();
        assert_eq!(got.code, "move_parallel(\"up\", 0.1)\n");
        assert_eq!(
            (got.block.index, got.block.blocks, got.block.candidates),
            (2, 3, 1)
        );
        assert!(matches!(
            extract_code("```json\n{\"a\": 1}\n```"),
            Err(ExtractError::NoPythonBlock { languages }) if languages == ["json"]
        ));
    }

    #[test]
    fn among_several_the_most_calls_then_the_last_wins() {
        let sketch = "```python\nclose_gripper()\n```";
        let full = "```python\nmove_gripper_to(\"a\")\nclose_gripper()\n```";
        let got = extract_code(&format!("{full}\nA detail:\n{sketch}")).unwrap();
        assert_eq!(got.block.index, 0);
        let got = extract_code(&format!("{sketch}\nCorrected:\n```python\nopen_gripper()\n```")).unwrap();
        assert_eq!((got.block.index, got.code.as_str()), (1, "open_gripper()\n"));
    }

    #[test]
    fn a_cut_off_block_runs_to_the_end() {
        let got = extract_code("Sure.\n```python\nmove_gripper_to(\"a\")\nclose_gr").unwrap();
        assert!(!got.block.terminated);
        assert_eq!(got.code, "move_gripper_to(\"a\")\nclose_gr\n");
    }

    #[test]
    fn indented_blocks_are_dedented() {
        let got = extract_code("1. The code:\n   ```python\n   for x in xs:\n       open_gripper()\n   ```")
            .unwrap();
        assert_eq!(got.code, "for x in xs:\n    open_gripper()\n");
    }

    #[test]
    fn errors_are_typed() {
        assert!(matches!(
            extract_code("I cannot write this program."),
            Err(ExtractError::NoCodeBlock { .. })
        ));
        assert!(matches!(
            extract_code("text\n```python\n\n```"),
            Err(ExtractError::EmptyBlock { line: 2 })
        ));
        assert!(matches!(
            extract_code("```python\nprint('hello')\n```"),
            Err(ExtractError::NoRobotCalls { line: 1 })
        ));
        // Inline code is not a fence.
        assert!(matches!(
            extract_code("Call ```close_gripper()``` now."),
            Err(ExtractError::NoCodeBlock { .. })
        ));
    }

    #[test]
    fn foreign_api_imports_are_stripped_and_recorded() {
        let reply = "```python\nimport numpy as np\nfrom robot import move_parallel\nfrom lmp_api import (\n    move_gripper_to,\n    close_gripper,\n)\nfrom robot_utils import *\nfrom helpers import plan_path\nimport time\nmove_gripper_to(\"a\")\nclose_gripper()\n```";
        let got = extract_code(reply).unwrap();
        assert_eq!(
            got.code,
            "import numpy as np\nfrom robot import move_parallel\nfrom helpers import plan_path\nimport time\nmove_gripper_to(\"a\")\nclose_gripper()\n"
        );
        assert_eq!(got.stripped.len(), 2);
        assert_eq!(got.stripped[0].line, 3);
        assert_eq!(
            got.stripped[0].text,
            "from lmp_api import (\n    move_gripper_to,\n    close_gripper,\n)"
        );
        assert!(got.stripped[0].reason.contains("`lmp_api`"));
        assert_eq!(got.stripped[1].text, "from robot_utils import *");
    }

    #[test]
    fn counting_calls_ignores_longer_names_and_mentions() {
        assert_eq!(
            count_api_calls("my_open_gripper()\nopen_gripper ()\n# open_gripper"),
            1
        );
    }
}
