//! The lexer: a formula's characters into numbers, names and symbols, each with the
//! characters it came from, so that every later error can put its caret under the right
//! one; and [`ParseError`], which it and the parser return. Apart from the parser: it
//! knows characters and the syntax of numbers, not the grammar.

use crate::limits::shorten;

/// A parse error: the character (0-based) and what is wrong there.
pub(super) struct ParseError {
    pub(super) at: usize,
    pub(super) message: String,
}

/// A token's kind: what the parser matches on.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Tok {
    Num(f64),
    Name(String),
    Sym(char),
    End,
}

/// A token and the characters it spans.
#[derive(Clone, Debug)]
pub(super) struct Token {
    pub(super) tok: Tok,
    /// Its first character.
    pub(super) at: usize,
    /// One past its last character.
    pub(super) end: usize,
}

/// The tokens of `chars`, ending with [`Tok::End`] at the formula's end.
pub(super) fn lex(chars: &[char]) -> Result<Vec<Token>, ParseError> {
    let n = chars.len();
    let digit = |i: usize| i < n && chars[i].is_ascii_digit();
    let mut out = Vec::new();
    let mut i = 0;
    while i < n {
        let c = chars[i];
        let at = i;
        if c.is_whitespace() {
            i += 1;
            continue;
        }
        if c.is_ascii_digit() || (c == '.' && digit(i + 1)) {
            while digit(i) {
                i += 1;
            }
            if i < n && chars[i] == '.' {
                i += 1;
                while digit(i) {
                    i += 1;
                }
            }
            if i < n && (chars[i] == 'e' || chars[i] == 'E') {
                let mut j = i + 1;
                if j < n && (chars[j] == '+' || chars[j] == '-') {
                    j += 1;
                }
                if !digit(j) {
                    return Err(ParseError {
                        at: i,
                        message: "a number's exponent needs digits (`1e-3`)".into(),
                    });
                }
                i = j;
                while digit(i) {
                    i += 1;
                }
            }
            let text: String = chars[at..i].iter().collect();
            let x: f64 = text.parse().map_err(|_| ParseError {
                at,
                message: format!("cannot read the number `{}`", shorten(&text)),
            })?;
            if !x.is_finite() {
                return Err(ParseError {
                    at,
                    message: format!(
                        "the number `{}` is too large (not finite as a 64-bit float)",
                        shorten(&text)
                    ),
                });
            }
            out.push(Token {
                tok: Tok::Num(x),
                at,
                end: i,
            });
        } else if c.is_ascii_alphabetic() || c == '_' {
            while i < n && (chars[i].is_ascii_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            out.push(Token {
                tok: Tok::Name(chars[at..i].iter().collect()),
                at,
                end: i,
            });
        } else if "+-*/^(),".contains(c) {
            i += 1;
            out.push(Token {
                tok: Tok::Sym(c),
                at,
                end: i,
            });
        } else {
            return Err(ParseError {
                at,
                message: format!(
                    "unexpected character `{}`: a formula has numbers, names, + - * / ^, parentheses and commas",
                    c.escape_debug()
                ),
            });
        }
    }
    out.push(Token {
        tok: Tok::End,
        at: n,
        end: n,
    });
    Ok(out)
}
