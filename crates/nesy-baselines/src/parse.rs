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
    let mut lines = text.lines().enumerate();
    let (open_line, fence) = lines
        .by_ref()
        .find_map(|(i, line)| {
            let trimmed = line.trim_start();
            let marker = trimmed.chars().next().filter(|c| *c == '`' || *c == '~')?;
            let run = trimmed.chars().take_while(|c| *c == marker).count();
            (run >= 3).then(|| (i + 1, marker.to_string().repeat(run)))
        })
        .ok_or(BlockError::NoBlock)?;
    let mut body = Vec::new();
    for (_, line) in lines {
        if line.trim() == fence {
            let block = body.join("\n").trim().to_string();
            return if block.is_empty() {
                Err(BlockError::Empty { line: open_line })
            } else {
                Ok(block)
            };
        }
        body.push(line);
    }
    Err(BlockError::Unclosed { line: open_line })
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
    fn a_block_must_open_and_close() {
        assert_eq!(first_block("prose"), Err(BlockError::NoBlock));
        assert_eq!(first_block("a\n```\nbody"), Err(BlockError::Unclosed { line: 2 }));
        assert_eq!(first_block("```\n\n```"), Err(BlockError::Empty { line: 1 }));
        assert_eq!(first_block("~~~~\nx\n```\ny\n~~~~").unwrap(), "x\n```\ny");
    }
}
