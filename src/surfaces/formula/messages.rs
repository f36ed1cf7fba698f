//! The words of a formula's errors: the formula on one line with a caret under the
//! character at fault, and why an instruction gave a value that is not finite. Apart from
//! the stages that find the errors (the parser when it folds constants, the evaluator on
//! the check's grid), which both describe them the same way here.

use super::compiler::{Fun, Op};
use crate::limits::shorten;

/// Why an instruction with finite inputs gave the non-finite `out`.
pub(super) fn failure(op: Op, inputs: &[f64], out: f64, snippet: &str) -> String {
    let s = format!("`{}`", shorten(snippet));
    let x = inputs.first().copied().unwrap_or(f64::NAN);
    match op {
        Op::Div if inputs.get(1) == Some(&0.0) => format!("{s} divides by zero"),
        Op::Call(Fun::Log) if x == 0.0 => format!("{s} takes the logarithm of zero"),
        Op::Call(Fun::Log) if x < 0.0 => {
            format!("{s} takes the logarithm of the negative number {x}")
        }
        Op::Call(Fun::Sqrt) if x < 0.0 => {
            format!("{s} takes the square root of the negative number {x}")
        }
        Op::Call(f @ (Fun::Asin | Fun::Acos)) if x.abs() > 1.0 => {
            format!("{s} takes {} of {x}, outside [-1, 1]", f.name())
        }
        Op::PowI(n) if x == 0.0 && n < 0 => format!("{s} raises zero to the negative power {n}"),
        Op::PowF(k) if x == 0.0 && k < 0.0 => {
            format!("{s} raises zero to the negative power {k}")
        }
        Op::PowF(k) if x < 0.0 => {
            format!("{s} raises the negative number {x} to the non-integer power {k}")
        }
        Op::Pow if x <= 0.0 => {
            format!("{s} raises {x} to a power that depends on u or v, which needs a positive base")
        }
        _ if out.is_nan() => format!("{s} is not a number"),
        _ => format!("{s} is infinite (it overflows)"),
    }
}

/// The formula on one line with a caret under character `at` (0-based; the length of the
/// formula for its end), indented by two spaces; a long formula shows about 60 characters
/// around `at`, with `...` where it is cut. Whitespace and control characters show as
/// spaces so that the caret stays under its character.
pub(super) fn caret(chars: &[char], at: usize) -> String {
    // With the `...` at both cuts, within the 60 bytes without whitespace that `shorten`
    // leaves whole (for ASCII).
    const WINDOW: usize = 50;
    let (mut start, mut end) = (0, chars.len());
    if chars.len() > WINDOW + 10 {
        start = at.saturating_sub(WINDOW / 2);
        end = (start + WINDOW).min(chars.len());
        start = end.saturating_sub(WINDOW).min(start);
    }
    let mut line = String::from("  ");
    let mut column = 2 + at - start;
    if start > 0 {
        line.push_str("...");
        column += 3;
    }
    line.extend(chars[start..end].iter().map(|&c| {
        if c.is_whitespace() || c.is_control() {
            ' '
        } else {
            c
        }
    }));
    if end < chars.len() {
        line.push_str("...");
    }
    format!("{line}\n{}^", " ".repeat(column))
}

#[cfg(test)]
mod tests {
    use super::super::tests::compile_error;

    #[test]
    fn a_long_formula_shows_a_window_around_the_caret() {
        let text = format!("{}u # {}", "u+".repeat(100), "v+".repeat(100));
        let e = compile_error(&text, &[]);
        let lines: Vec<&str> = e.lines().collect();
        assert_eq!(lines.len(), 3, "{e}");
        assert!(
            lines[0].contains("character 203: unexpected character `#`"),
            "{e}"
        );
        assert!(
            lines[1].starts_with("  ...") && lines[1].ends_with("..."),
            "{e}"
        );
        assert!(lines[1].chars().count() < 80, "{e}");
        let column = lines[2].len() - 1;
        assert!(lines[2].ends_with('^') && lines[2].trim() == "^", "{e}");
        assert_eq!(lines[1].chars().nth(column), Some('#'), "{e}");
        // Near either end the window keeps that end, unmarked.
        let e = compile_error(&format!("#{}", "+u".repeat(100)), &[]);
        let lines: Vec<&str> = e.lines().collect();
        assert!(
            lines[1].starts_with("  #+u") && lines[1].ends_with("..."),
            "{e}"
        );
        assert_eq!(lines[2], "  ^");
        // Tabs and newlines show as spaces, so the caret stays under its character.
        assert_eq!(
            compile_error("u\t+\n#", &[]),
            "cannot read the formula at character 5: unexpected character `#`: a formula has numbers, names, + - * / ^, parentheses and commas\n  u + #\n      ^"
        );
    }
}
