//! The parser: recursive descent over the tokens. There is no syntax tree: the descent
//! emits the postfix instructions of a [`Program`] as it goes, resolves every name (u, v,
//! `pi`, `e`, the parameters, the functions and their number of arguments), folds constant
//! parts into numbers and enforces the limits a formula meets when it is compiled
//! ([`FORMULA_DEPTH`], [`FORMULA_EXPONENT`]). Apart from the lexer, which knows characters,
//! and from the compiler, which knows what the instructions are.
//!
//! Hand-written rather than taken from a crate; the module doc of [`formula`](super) says
//! why (the expression crates evaluate f64 only or tie their numbers to dynamic values, and
//! none gives the character positions a caret needs).

use super::compiler::{FUNCTIONS, Op, Program, function};
use super::evaluator::exec;
use super::lexer::{ParseError, Tok, Token, lex};
use super::messages::failure;
use crate::limits::{FORMULA_DEPTH, FORMULA_EXPONENT, shorten};
use std::collections::BTreeMap;
use std::f64::consts::{E, PI};

/// Recursive descent over the tokens, emitting postfix code:
///
/// ```text
/// expr    = term (("+" | "-") term)*
/// term    = unary (("*" | "/") unary)*
/// unary   = ("-" | "+") unary | power
/// power   = primary ("^" unary)?          right-associative, above unary minus
/// primary = number | name | name "(" expr ("," expr)* ")" | "(" expr ")"
/// ```
pub(super) struct Parser<'a> {
    chars: &'a [char],
    toks: Vec<Token>,
    k: usize,
    /// One past the last character consumed.
    end: usize,
    parameters: &'a BTreeMap<String, f64>,
    ops: Vec<Op>,
    spans: Vec<(usize, usize)>,
    depth: usize,
}

impl<'a> Parser<'a> {
    /// The program of the formula `chars`, or where and why it does not parse.
    pub(super) fn run(
        chars: &'a [char],
        parameters: &'a BTreeMap<String, f64>,
    ) -> Result<Program, ParseError> {
        let mut p = Parser {
            chars,
            toks: lex(chars)?,
            k: 0,
            end: 0,
            parameters,
            ops: Vec::new(),
            spans: Vec::new(),
            depth: 0,
        };
        p.expr()?;
        let t = p.peek().clone();
        match t.tok {
            Tok::End => {}
            Tok::Sym(')') => return Err(p.error(&t, "unmatched `)`: no `(` before it".into())),
            _ => {
                let found = p.describe(&t);
                return Err(p.error(
                    &t,
                    format!("expected an operator (+ - * / ^) or the end, found {found}"),
                ));
            }
        }
        let (mut sp, mut depth) = (0usize, 0usize);
        for op in &p.ops {
            sp = sp + 1 - op.arity();
            depth = depth.max(sp);
        }
        Ok(Program {
            ops: p.ops,
            spans: p.spans,
            text: chars.to_vec(),
            depth,
        })
    }

    fn peek(&self) -> &Token {
        &self.toks[self.k.min(self.toks.len() - 1)]
    }

    fn next(&mut self) -> Token {
        let t = self.peek().clone();
        if self.k < self.toks.len() - 1 {
            self.k += 1;
            self.end = t.end;
        }
        t
    }

    fn at_sym(&self, c: char) -> bool {
        self.peek().tok == Tok::Sym(c)
    }

    fn describe(&self, t: &Token) -> String {
        match &t.tok {
            Tok::End => "the end".into(),
            _ => {
                let text: String = self.chars[t.at..t.end].iter().collect();
                format!("`{}`", shorten(&text))
            }
        }
    }

    fn error(&self, t: &Token, message: String) -> ParseError {
        ParseError { at: t.at, message }
    }

    /// Appends an instruction computing the characters `span`, or folds it into a number
    /// when its operands are numbers (a constant part is then always one `Const`, which
    /// is how `^` knows its exponent is constant).
    fn emit(&mut self, op: Op, span: (usize, usize)) -> Result<(), ParseError> {
        let (k, n) = (op.arity(), self.ops.len());
        let constant = k > 0 && self.ops[n - k..].iter().all(|o| matches!(o, Op::Const(_)));
        if !constant {
            self.ops.push(op);
            self.spans.push(span);
            return Ok(());
        }
        let mut s: Vec<f64> = self.ops[n - k..]
            .iter()
            .map(|o| if let Op::Const(x) = o { *x } else { f64::NAN })
            .collect();
        let inputs = s.clone();
        let mut sp = k;
        exec(op, &mut s, &mut sp, 0.0, 0.0);
        let x = s[0];
        if !x.is_finite() {
            let snippet: String = self.chars[span.0..span.1].iter().collect();
            return Err(ParseError {
                at: span.0,
                message: failure(op, &inputs, x, &snippet),
            });
        }
        self.ops.truncate(n - k);
        self.spans.truncate(n - k);
        self.ops.push(Op::Const(x));
        self.spans.push(span);
        Ok(())
    }

    fn expr(&mut self) -> Result<usize, ParseError> {
        let start = self.term()?;
        loop {
            let op = match self.peek().tok {
                Tok::Sym('+') => Op::Add,
                Tok::Sym('-') => Op::Sub,
                _ => return Ok(start),
            };
            self.next();
            self.term()?;
            self.emit(op, (start, self.end))?;
        }
    }

    fn term(&mut self) -> Result<usize, ParseError> {
        let start = self.unary()?;
        loop {
            let op = match self.peek().tok {
                Tok::Sym('*') => Op::Mul,
                Tok::Sym('/') => Op::Div,
                _ => return Ok(start),
            };
            self.next();
            self.unary()?;
            self.emit(op, (start, self.end))?;
        }
    }

    fn unary(&mut self) -> Result<usize, ParseError> {
        self.depth += 1;
        if self.depth > FORMULA_DEPTH {
            let t = self.peek().clone();
            return Err(self.error(
                &t,
                format!(
                    "the formula nests parentheses, powers and signs deeper than {FORMULA_DEPTH} levels"
                ),
            ));
        }
        let start = if self.at_sym('-') {
            let t = self.next();
            self.unary()?;
            self.emit(Op::Neg, (t.at, self.end))?;
            t.at
        } else if self.at_sym('+') {
            let t = self.next();
            self.unary()?;
            t.at
        } else {
            self.power()?
        };
        self.depth -= 1;
        Ok(start)
    }

    fn power(&mut self) -> Result<usize, ParseError> {
        let start = self.primary()?;
        if !self.at_sym('^') {
            return Ok(start);
        }
        self.next();
        let exponent = self.peek().clone();
        self.unary()?;
        let span = (start, self.end);
        match self.ops.last() {
            Some(&Op::Const(k)) => {
                if k.abs() > FORMULA_EXPONENT {
                    return Err(self.error(
                        &exponent,
                        format!(
                            "the exponent {k:e} is larger than {FORMULA_EXPONENT:e} in size: x^k changes by a factor e when x changes by 1/k of itself, narrower than any mesh resolves"
                        ),
                    ));
                }
                self.ops.pop();
                self.spans.pop();
                let op = if k.fract() == 0.0 {
                    Op::PowI(k as i32)
                } else {
                    Op::PowF(k)
                };
                self.emit(op, span)?;
            }
            _ => self.emit(Op::Pow, span)?,
        }
        Ok(start)
    }

    fn primary(&mut self) -> Result<usize, ParseError> {
        let t = self.next();
        match &t.tok {
            Tok::Num(x) => {
                self.emit(Op::Const(*x), (t.at, t.end))?;
            }
            Tok::Sym('(') => {
                self.expr()?;
                if !self.at_sym(')') {
                    let found = self.peek().clone();
                    let what = self.describe(&found);
                    return Err(self.error(
                        &found,
                        format!(
                            "expected `)` to close the `(` at character {}, found {what}",
                            t.at + 1
                        ),
                    ));
                }
                self.next();
            }
            Tok::Name(name) => self.name(&t, name)?,
            _ => {
                let found = self.describe(&t);
                return Err(self.error(
                    &t,
                    format!("expected a number, a name or `(`, found {found}"),
                ));
            }
        }
        Ok(t.at)
    }

    fn name(&mut self, t: &Token, name: &str) -> Result<(), ParseError> {
        let called = self.at_sym('(');
        let Some(f) = function(name) else {
            let op = match name {
                "u" => Op::U,
                "v" => Op::V,
                "pi" => Op::Const(PI),
                "e" => Op::Const(E),
                _ => match self.parameters.get(name) {
                    Some(x) => Op::Const(*x),
                    None => return Err(self.error(t, self.unknown(name))),
                },
            };
            if called {
                return Err(self.error(
                    t,
                    format!("`{name}` is not a function: write `{name}*(...)` to multiply"),
                ));
            }
            return self.emit(op, (t.at, t.end));
        };
        if !called {
            return Err(self.error(t, format!("`{name}` is a function: write `{name}(...)`")));
        }
        let open = self.next();
        let mut args = 0;
        if !self.at_sym(')') {
            loop {
                self.expr()?;
                args += 1;
                if self.at_sym(',') {
                    self.next();
                    continue;
                }
                if self.at_sym(')') {
                    break;
                }
                let found = self.peek().clone();
                let what = self.describe(&found);
                let expected = if args < f.arity() {
                    format!("`,` or `)` to close the `(` of `{name}`")
                } else {
                    "`)` to close the `(`".to_string()
                };
                return Err(self.error(
                    &found,
                    format!(
                        "expected {expected} at character {}, found {what}",
                        open.at + 1
                    ),
                ));
            }
        }
        self.next();
        if args != f.arity() {
            let want = match f.arity() {
                1 => "1 argument".to_string(),
                n => format!("{n} arguments"),
            };
            return Err(self.error(t, format!("`{name}` takes {want}, got {args}")));
        }
        self.emit(Op::Call(f), (t.at, self.end))
    }

    /// The message for an unknown name, with the closest known one.
    fn unknown(&self, name: &str) -> String {
        let shown = shorten(name);
        let known = ["u", "v"]
            .into_iter()
            .chain(self.parameters.keys().map(String::as_str))
            .chain(["pi", "e"])
            .chain(FUNCTIONS.iter().map(|(n, _)| *n));
        // A name that differs only in case comes first (`R` for the parameter `r`).
        let best = known
            .map(|k| {
                let case = !k.eq_ignore_ascii_case(name);
                (edit_distance(name, k), case, k)
            })
            .min_by_key(|&(d, case, _)| (d, case))
            .map(|(d, _, k)| (d, k));
        match best {
            Some((d, k)) if d <= name.chars().count().div_ceil(2).max(1) => {
                format!("unknown name `{shown}`; did you mean `{k}`?")
            }
            _ => format!(
                "unknown name `{shown}`: the names are u, v, pi, e, the parameters and the functions {}",
                FUNCTIONS.map(|(n, _)| n).join(", ")
            ),
        }
    }
}

/// Levenshtein distance over characters.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let next = (diagonal + usize::from(ca != *cb))
                .min(row[j] + 1)
                .min(row[j + 1] + 1);
            diagonal = row[j + 1];
            row[j + 1] = next;
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::super::tests::compile_error;
    use super::edit_distance;

    #[test]
    fn parse_errors_point_at_the_character() {
        assert_eq!(
            compile_error("sin(u", &[]),
            "cannot read the formula at character 6: expected `)` to close the `(` at character 4, found the end\n  sin(u\n       ^"
        );
        assert_eq!(
            compile_error("sine(u)", &[]),
            "cannot read the formula at character 1: unknown name `sine`; did you mean `sin`?\n  sine(u)\n  ^"
        );
        assert_eq!(
            compile_error("2*alpha", &[("alfa", 1.0)]),
            "cannot read the formula at character 3: unknown name `alpha`; did you mean `alfa`?\n  2*alpha\n    ^"
        );
        let e = compile_error("zzzzzz", &[]);
        assert!(
            e.contains("unknown name `zzzzzz`: the names are u, v, pi, e"),
            "{e}"
        );
        assert_eq!(
            compile_error("1 + atan2(u)", &[]),
            "cannot read the formula at character 5: `atan2` takes 2 arguments, got 1\n  1 + atan2(u)\n      ^"
        );
        assert!(compile_error("sin(u, v)", &[]).contains("`sin` takes 1 argument, got 2"));
        assert!(compile_error("max()", &[]).contains("`max` takes 2 arguments, got 0"));
        assert_eq!(
            compile_error("2*sin", &[]),
            "cannot read the formula at character 3: `sin` is a function: write `sin(...)`\n  2*sin\n    ^"
        );
        assert!(compile_error("u(1)", &[]).contains("`u` is not a function: write `u*(...)`"));
        assert_eq!(
            compile_error("2u", &[]),
            "cannot read the formula at character 2: expected an operator (+ - * / ^) or the end, found `u`\n  2u\n   ^"
        );
        assert!(compile_error("u)", &[]).contains("character 2: unmatched `)`"));
        assert!(
            compile_error("u^", &[])
                .contains("character 3: expected a number, a name or `(`, found the end")
        );
        assert!(compile_error("", &[]).contains("character 1: expected a number"));
        assert!(compile_error("u # v", &[]).contains("character 3: unexpected character `#`"));
        assert!(
            compile_error("1e999*u", &[]).contains("character 1: the number `1e999` is too large")
        );
        assert!(
            compile_error("2e+", &[]).contains("character 2: a number's exponent needs digits")
        );
        assert!(compile_error("min(u v)", &[]).contains(
            "character 7: expected `,` or `)` to close the `(` of `min` at character 4, found `v`"
        ));
        // Constant parts that are not finite are caught when they are folded.
        assert_eq!(
            compile_error("u + 1/(2-2)", &[]),
            "cannot read the formula at character 5: `1/(2-2)` divides by zero\n  u + 1/(2-2)\n      ^"
        );
        assert!(
            compile_error("log(-1)*u", &[])
                .contains("`log(-1)` takes the logarithm of the negative number -1")
        );
        assert!(
            compile_error("(-8)^(1/3)", &[])
                .contains("raises the negative number -8 to the non-integer power")
        );
        let e = compile_error("sin(u)^1e9", &[]);
        assert!(
            e.starts_with(
                "cannot read the formula at character 8: the exponent 1e9 is larger than 1e6"
            ),
            "{e}"
        );
        assert!(e.ends_with("  sin(u)^1e9\n         ^"), "{e}");
        let e = compile_error("sin(u)^a", &[("a", -2e6)]);
        assert!(e.contains("the exponent -2e6 is larger than 1e6"), "{e}");
    }

    #[test]
    fn edit_distance_counts_edits() {
        assert_eq!(edit_distance("sine", "sin"), 1);
        assert_eq!(edit_distance("alpha", "alfa"), 2);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("kitten", "sitting"), 3);
    }
}
