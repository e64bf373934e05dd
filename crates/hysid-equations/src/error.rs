//! The one error type of the crate: a one-line message with its place in the model file.

/// A problem in a model file, located at a line and column of the file.
///
/// Displayed as `line L, column C: message`, on one line. Lines and columns count from 1;
/// columns count characters (not bytes) and point into the file itself, also inside
/// expression strings (`"k*xx"` points at the `x` of `xx`).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("line {line}, column {column}: {message}")]
pub struct EquationError {
    /// 1-based line in the file.
    pub line: usize,
    /// 1-based column (in characters) in the line.
    pub column: usize,
    /// What is wrong and what to do about it (one line).
    pub message: String,
}

impl EquationError {
    /// The error `message` at byte `offset` of `text` (clamped into the text).
    pub(crate) fn at(text: &str, offset: usize, message: impl Into<String>) -> Self {
        let (line, column) = line_column(text, offset);
        let message: String = message.into();
        // One line, whatever the message carried (toml's messages can span lines).
        let message = message
            .lines()
            .map(str::trim)
            .filter(|l| !l.is_empty())
            .collect::<Vec<_>>()
            .join("; ");
        EquationError {
            line,
            column,
            message,
        }
    }
}

/// 1-based (line, column in characters) of byte `offset` in `text`.
pub(crate) fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let mut offset = offset.min(text.len());
    while !text.is_char_boundary(offset) {
        offset -= 1;
    }
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let column = text[line_start..offset].chars().count() + 1;
    (line, column)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_and_column_count_characters_from_one() {
        let text = "ab\ncé d\n";
        assert_eq!(line_column(text, 0), (1, 1));
        assert_eq!(line_column(text, 3), (2, 1));
        // 'd' is at byte 7 (é is two bytes) and character column 4.
        assert_eq!(line_column(text, 7), (2, 4));
        assert_eq!(line_column(text, 1000), (3, 1));
    }

    #[test]
    fn messages_are_one_line() {
        let e = EquationError::at("x", 0, "first\n  second\n");
        assert_eq!(e.to_string(), "line 1, column 1: first; second");
    }
}
