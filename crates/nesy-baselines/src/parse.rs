//! The authors' three reply readers, made total: each returns the answer or says why there
//! is none, and never panics. Every reply is read after `**` is removed (as the authors do)
//! and after [`nesy_core::text::normalize_reply`] (a `<think>` section, Unicode bullets and
//! dashes, curly quotes).

use nesy_core::text::normalize_reply;

/// The text a reader sees: the reply without markdown bold and with its typography undone.
pub fn prepared(reply: &str) -> String {
    normalize_reply(&reply.replace("**", ""))
}

/// The items of the numbered list in `reply`: every line that, trimmed, starts with digits
/// and a `.`, with the number and the space after it removed. Empty items are skipped.
///
/// ```
/// let reply = "Reasoning first.\n\n1. Grasp the cube.\n 2.  Put it in the box.\n3.";
/// assert_eq!(
///     nesy_baselines::parse::ordered_list(reply),
///     ["Grasp the cube.", "Put it in the box."]
/// );
/// ```
pub fn ordered_list(reply: &str) -> Vec<String> {
    prepared(reply)
        .lines()
        .filter_map(|line| {
            let line = line.trim();
            let digits = line.len() - line.trim_start_matches(|c: char| c.is_ascii_digit()).len();
            let rest = line[digits..].strip_prefix('.')?;
            (digits > 0).then(|| rest.trim().to_string())
        })
        .filter(|item| !item.is_empty())
        .collect()
}

/// The items of the bulleted list in `reply`: every line that starts with `-` (not indented,
/// as the authors read it), without the leading dashes and spaces. Empty items are skipped.
///
/// ```
/// let reply = "Rationale.\n- The gripper holds the cube.\n  - an indented note\n-";
/// assert_eq!(nesy_baselines::parse::unordered_list(reply), ["The gripper holds the cube."]);
/// ```
pub fn unordered_list(reply: &str) -> Vec<String> {
    prepared(reply)
        .lines()
        .filter(|line| line.starts_with('-'))
        .map(|line| line.trim_start_matches(['-', ' ']).trim().to_string())
        .filter(|item| !item.is_empty())
        .collect()
}

/// Why a fenced block could not be taken from a reply.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum BlockError {
    /// The reply has no fence.
    #[error("it has no fenced block (``` on its own line before and after the text)")]
    NoBlock,
    /// The first block opens on `line` and is never closed.
    #[error("its fenced block opened on line {line} is never closed")]
    Unclosed {
        /// 1-based line of the opening fence.
        line: usize,
    },
    /// The first block holds nothing.
    #[error("its fenced block on line {line} is empty")]
    Empty {
        /// 1-based line of the opening fence.
        line: usize,
    },
}

/// The text of the first fenced block of `reply` (opened by three or more backticks or
/// tildes, any language tag, closed by the same fence), trimmed.
///
/// ```
/// let reply = "Here it is.\n```text\nTask: stack the cubes.\n```\nDone.";
/// assert_eq!(nesy_baselines::parse::first_block(reply).unwrap(), "Task: stack the cubes.");
/// ```
pub fn first_block(reply: &str) -> Result<String, BlockError> {
    let text = prepared(reply);
    next_block(&mut text.lines().enumerate()).unwrap_or(Err(BlockError::NoBlock))
}

/// The texts of every closed fenced block of `reply`, in order (trimmed; empty ones left
/// out).
///
/// ```
/// let reply = "Initial state\n```\n(:objects a b)\n```\n```\n(:init (on a b))\n```";
/// assert_eq!(nesy_baselines::parse::blocks(reply), ["(:objects a b)", "(:init (on a b))"]);
/// ```
pub fn blocks(reply: &str) -> Vec<String> {
    let text = prepared(reply);
    let mut lines = text.lines().enumerate();
    let mut out = Vec::new();
    while let Some(block) = next_block(&mut lines) {
        match block {
            Ok(block) => out.push(block),
            Err(BlockError::Empty { .. }) => {}
            Err(_) => break,
        }
    }
    out
}

/// The next fenced block of `lines` (opened by three or more backticks or tildes, closed by
/// the same fence), consuming the lines up to its closing fence; `None` when no fence opens.
fn next_block<'a>(lines: &mut impl Iterator<Item = (usize, &'a str)>) -> Option<Result<String, BlockError>> {
    let (open_line, fence) = lines.find_map(|(i, line)| {
        let trimmed = line.trim_start();
        let marker = trimmed.chars().next().filter(|c| *c == '`' || *c == '~')?;
        let run = trimmed.chars().take_while(|c| *c == marker).count();
        (run >= 3).then(|| (i + 1, marker.to_string().repeat(run)))
    })?;
    let mut body = Vec::new();
    for (_, line) in lines {
        if line.trim() == fence {
            let block = body.join("\n").trim().to_string();
            return Some(if block.is_empty() {
                Err(BlockError::Empty { line: open_line })
            } else {
                Ok(block)
            });
        }
        body.push(line);
    }
    Some(Err(BlockError::Unclosed { line: open_line }))
}

/// One text edit of a plan: lines to find and the lines that replace them.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LinePatch {
    /// The lines to find, trimmed.
    pub search: Vec<String>,
    /// The lines that replace them, trimmed, empty ones left out.
    pub replace: Vec<String>,
}

/// Every `<<<<<<< SEARCH … ======= … >>>>>>> REPLACE` block of `text`, in order. A block
/// whose markers are incomplete is not an edit and is skipped, as the authors' pattern
/// would not match it.
///
/// ```
/// use nesy_baselines::parse::line_patches;
/// let text = "<<<<<<< SEARCH\nGrasp the cube.\n=======\nClear the cube.\nGrasp the cube.\n>>>>>>> REPLACE";
/// let patches = line_patches(text);
/// assert_eq!(patches[0].search, ["Grasp the cube."]);
/// assert_eq!(patches[0].replace, ["Clear the cube.", "Grasp the cube."]);
/// ```
pub fn line_patches(text: &str) -> Vec<LinePatch> {
    let text = prepared(text);
    let mut patches = Vec::new();
    let mut rest = text.as_str();
    while let Some(start) = rest.find("<<<<<<< SEARCH") {
        let after = &rest[start + "<<<<<<< SEARCH".len()..];
        let (Some(divider), Some(end)) = (after.find("======="), after.find(">>>>>>> REPLACE")) else {
            break;
        };
        if divider > end {
            rest = &after[end..];
            continue;
        }
        let lines = |block: &str| -> Vec<String> {
            block
                .lines()
                .map(str::trim)
                .filter(|l| !l.is_empty())
                .map(str::to_string)
                .collect()
        };
        patches.push(LinePatch {
            search: lines(&after[..divider]),
            replace: lines(&after[divider + "=======".len()..end]),
        });
        rest = &after[end + ">>>>>>> REPLACE".len()..];
    }
    patches
}

/// Applies each patch at the first place its lines appear, in order and exactly; a patch that
/// matches nowhere leaves the plan as it is. Returns how many applied.
pub fn apply_line_patches(plan: &mut Vec<String>, patches: &[LinePatch]) -> usize {
    let mut applied = 0;
    for patch in patches {
        let n = patch.search.len();
        if n == 0 || n > plan.len() {
            continue;
        }
        if let Some(at) = (0..=plan.len() - n).find(|&i| plan[i..i + n] == patch.search[..]) {
            plan.splice(at..at + n, patch.replace.iter().cloned());
            applied += 1;
        }
    }
    applied
}

/// `line` without a leading `N.` list number.
pub fn without_number(line: &str) -> &str {
    let trimmed = line.trim_start();
    let digits = trimmed.len() - trimmed.trim_start_matches(|c: char| c.is_ascii_digit()).len();
    match trimmed[digits..].strip_prefix('.') {
        Some(rest) if digits > 0 => rest.trim_start(),
        _ => line,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_read_through_markdown_and_unicode_bullets() {
        let reply = "**Plan:**\n1. **Grasp** the cube\n2) not this one\n10. Release";
        assert_eq!(ordered_list(reply), ["Grasp the cube", "Release"]);
        let reply = "\u{2022} The lid is open.\n* not a dash\n- (OnTopOf a b)";
        assert_eq!(unordered_list(reply), ["The lid is open.", "(OnTopOf a b)"]);
        assert!(ordered_list("no list here").is_empty());
    }

    #[test]
    fn line_patches_match_exactly_at_the_first_place() {
        let mut plan: Vec<String> = ["a", "b", "a"].map(String::from).to_vec();
        let text = "x\n<<<<<<< SEARCH\na\n=======\nz\n\na\n>>>>>>> REPLACE\n<<<<<<< SEARCH\nq\n=======\n>>>>>>> REPLACE\n<<<<<<< SEARCH\nbroken";
        let patches = line_patches(text);
        assert_eq!(patches.len(), 2);
        assert_eq!(apply_line_patches(&mut plan, &patches), 1);
        assert_eq!(plan, ["z", "a", "b", "a"]);
        assert_eq!(without_number("3. Grasp"), "Grasp");
        assert_eq!(without_number("Grasp 3."), "Grasp 3.");
    }

    #[test]
    fn a_block_must_open_and_close() {
        assert_eq!(first_block("prose"), Err(BlockError::NoBlock));
        assert_eq!(first_block("a\n```\nbody"), Err(BlockError::Unclosed { line: 2 }));
        assert_eq!(first_block("```\n\n```"), Err(BlockError::Empty { line: 1 }));
        assert_eq!(first_block("~~~~\nx\n```\ny\n~~~~").unwrap(), "x\n```\ny");
    }
}
