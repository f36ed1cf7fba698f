//! The evaluator: compiled formulas run over f64 (points), over [`Jet`]s (points with
//! their exact first and second derivatives), over [`Interval`]s (enclosures of their
//! values over boxes of parameters) and over jets of intervals (enclosures of their values
//! and derivatives), without recursion and without string work;
//! and, when a value is not finite, the instruction that made it so. Apart from the
//! compiler: what runs once per point, against what runs once per formula.

use super::compiler::{Fun, Node, Op, Program, Shared};
use super::messages::failure;
use crate::limits::shorten;
use crate::surfaces::{Interval, Jet};
use std::ops::{Add, Div, Mul, Neg, Sub};

/// What a formula computes with: f64 for points, [`Jet`] for derivatives, [`Interval`]
/// and jets of them for enclosures. The first two take the same steps, so that a point is
/// bit for bit the value of its jet.
pub(super) trait Number:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    fn constant(x: f64) -> Self;
    fn int_power(self, n: i32) -> Self;
    fn real_power(self, k: f64) -> Self;
    fn power(self, y: Self) -> Self;
    fn scale(self, k: f64) -> Self;
    fn shift(self, k: f64) -> Self;
    fn over(self, k: f64) -> Self;
    fn call1(f: Fun, a: Self) -> Self;
    fn call2(f: Fun, a: Self, b: Self) -> Self;
}

impl Number for f64 {
    fn constant(x: f64) -> Self {
        x
    }
    fn int_power(self, n: i32) -> Self {
        self.powi(n)
    }
    fn real_power(self, k: f64) -> Self {
        self.powf(k)
    }
    fn power(self, y: Self) -> Self {
        (y * self.ln()).exp()
    }
    fn scale(self, k: f64) -> Self {
        self * k
    }
    fn shift(self, k: f64) -> Self {
        self + k
    }
    fn over(self, k: f64) -> Self {
        self / k
    }
    fn call1(f: Fun, a: Self) -> Self {
        match f {
            Fun::Sin => a.sin(),
            Fun::Cos => a.cos(),
            Fun::Tan => a.tan(),
            Fun::Asin => a.asin(),
            Fun::Acos => a.acos(),
            Fun::Atan => a.atan(),
            Fun::Sinh => a.sinh(),
            Fun::Cosh => a.cosh(),
            Fun::Tanh => a.tanh(),
            Fun::Exp => a.exp(),
            Fun::Log => a.ln(),
            Fun::Sqrt => a.sqrt(),
            Fun::Abs => {
                if a < 0.0 {
                    -a
                } else {
                    a
                }
            }
            Fun::Atan2 | Fun::Min | Fun::Max => f64::NAN,
        }
    }
    fn call2(f: Fun, a: Self, b: Self) -> Self {
        match f {
            Fun::Atan2 => a.atan2(b),
            Fun::Min => {
                if b < a {
                    b
                } else {
                    a
                }
            }
            Fun::Max => {
                if b > a {
                    b
                } else {
                    a
                }
            }
            _ => f64::NAN,
        }
    }
}

/// `call1` and `call2` of a [`Number`] whose functions are its methods of the same names
/// (`ln` for `log`), with `undefined` for a function called with the wrong number of
/// arguments (which the compiler refuses).
macro_rules! calls {
    ($undefined:expr) => {
        fn call1(f: Fun, a: Self) -> Self {
            match f {
                Fun::Sin => a.sin(),
                Fun::Cos => a.cos(),
                Fun::Tan => a.tan(),
                Fun::Asin => a.asin(),
                Fun::Acos => a.acos(),
                Fun::Atan => a.atan(),
                Fun::Sinh => a.sinh(),
                Fun::Cosh => a.cosh(),
                Fun::Tanh => a.tanh(),
                Fun::Exp => a.exp(),
                Fun::Log => a.ln(),
                Fun::Sqrt => a.sqrt(),
                Fun::Abs => a.abs(),
                Fun::Atan2 | Fun::Min | Fun::Max => $undefined,
            }
        }
        fn call2(f: Fun, a: Self, b: Self) -> Self {
            match f {
                Fun::Atan2 => a.atan2(b),
                Fun::Min => a.min(b),
                Fun::Max => a.max(b),
                _ => $undefined,
            }
        }
    };
}

/// A [`Number`] of jets over the scalar `$s`, whose undefined value is `$undefined` and
/// whose constant real powers are `$real_power`.
macro_rules! jets {
    ($s:ty, $undefined:expr, $real_power:expr) => {
        impl Number for Jet<$s> {
            fn constant(x: f64) -> Self {
                Jet::from(x)
            }
            fn int_power(self, n: i32) -> Self {
                self.powi(n)
            }
            fn real_power(self, k: f64) -> Self {
                $real_power(self, k)
            }
            fn power(self, y: Self) -> Self {
                self.pow(y)
            }
            fn scale(self, k: f64) -> Self {
                Jet::scale(self, k)
            }
            fn shift(self, k: f64) -> Self {
                self + k
            }
            fn over(self, k: f64) -> Self {
                Jet::over(self, k)
            }
            calls!(Jet::constant($undefined));
        }
    };
}

jets!(f64, f64::NAN, Jet::powf);
jets!(Interval, Interval::ENTIRE, |x: Jet<Interval>, k: f64| {
    // As for intervals: an integral power is defined for negative bases.
    match integral(k) {
        Some(n) => x.powi(n),
        None => x.powf(k),
    }
});

/// `k` as an i32 where it is one (what f64's `powf` takes as an integer power).
fn integral(k: f64) -> Option<i32> {
    (k.fract() == 0.0 && k.abs() <= f64::from(i32::MAX)).then_some(k as i32)
}

/// Enclosures: the constants are the f64 values the compiler folded them to (`pi` the f64
/// nearest π), and the formula over them is enclosed exactly as real arithmetic would
/// compute it. What is undefined somewhere on a box (a logarithm reaching 0, `min`'s
/// unused one-argument form) is the whole line there.
impl Number for Interval {
    fn constant(x: f64) -> Self {
        Interval::point(x)
    }
    fn int_power(self, n: i32) -> Self {
        self.powi(n)
    }
    fn real_power(self, k: f64) -> Self {
        // An integral power is defined for negative bases, as f64's `powf` takes it.
        match integral(k) {
            Some(n) => self.powi(n),
            None => self.powf(k),
        }
    }
    fn power(self, y: Self) -> Self {
        self.pow(y)
    }
    fn scale(self, k: f64) -> Self {
        self * Interval::point(k)
    }
    fn shift(self, k: f64) -> Self {
        self + Interval::point(k)
    }
    fn over(self, k: f64) -> Self {
        self / Interval::point(k)
    }
    calls!(Interval::ENTIRE);
}

/// Runs one instruction on the stack `s` whose first `sp` entries are live.
pub(super) fn exec<T: Number>(op: Op, s: &mut [T], sp: &mut usize, u: T, v: T) {
    let n = op.arity();
    let (a, b) = match n {
        0 => (u, v),
        1 => (s[*sp - 1], s[*sp - 1]),
        _ => (s[*sp - 2], s[*sp - 1]),
    };
    *sp -= n;
    s[*sp] = apply(op, a, b, u, v);
    *sp += 1;
}

impl Shared {
    /// The four coordinates at (u, v).
    pub(super) fn run<T: Number>(&self, u: T, v: T) -> [T; 4] {
        // The registers live on the machine stack, in the smallest of a few sizes (filling
        // them first costs little against the nodes: measured as fast as filling them as
        // the nodes go).
        match self.nodes.len() {
            0..=16 => self.run_in::<T, 16>(u, v),
            17..=32 => self.run_in::<T, 32>(u, v),
            33..=64 => self.run_in::<T, 64>(u, v),
            n => {
                let mut r = vec![T::constant(0.0); n];
                self.run_on(&mut r, u, v)
            }
        }
    }

    fn run_in<T: Number, const N: usize>(&self, u: T, v: T) -> [T; 4] {
        self.run_on(&mut [T::constant(0.0); N], u, v)
    }

    /// Runs the nodes on registers `r` (at least one per node).
    fn run_on<T: Number>(&self, r: &mut [T], u: T, v: T) -> [T; 4] {
        (r[0], r[1]) = (u, v);
        for (i, &(node, args)) in self.nodes.iter().enumerate().skip(2) {
            r[i] = node_value(node, args, &r[..i]);
        }
        self.outputs.map(|o| r[o as usize])
    }
}

/// A node's value from the registers of the nodes before it.
#[inline(always)]
fn node_value<T: Number>(node: Node, [a, b]: [u32; 2], r: &[T]) -> T {
    // One match over every kind of node (no second dispatch on the instruction).
    let x = || r[a as usize];
    let y = || r[b as usize];
    match node {
        Node::Op(Op::Const(c)) => T::constant(c),
        // Registers 0 and 1, set before the nodes run.
        Node::Op(Op::U) => r[0],
        Node::Op(Op::V) => r[1],
        Node::Op(Op::Neg) => -x(),
        Node::Op(Op::Add) => x() + y(),
        Node::Op(Op::Sub) => x() - y(),
        Node::Op(Op::Mul) => x() * y(),
        Node::Op(Op::Div) => x() / y(),
        Node::Op(Op::PowI(n)) => x().int_power(n),
        Node::Op(Op::PowF(k)) => x().real_power(k),
        Node::Op(Op::Pow) => x().power(y()),
        Node::Op(Op::Call(f)) if f.arity() == 1 => T::call1(f, x()),
        Node::Op(Op::Call(f)) => T::call2(f, x(), y()),
        Node::Scale(k) => x().scale(k),
        Node::Shift(k) => x().shift(k),
        Node::Over(k) => x().over(k),
    }
}

/// One instruction on its operands (`a` and `b`, as many as it takes).
#[inline]
fn apply<T: Number>(op: Op, a: T, b: T, u: T, v: T) -> T {
    match op {
        Op::Const(x) => T::constant(x),
        Op::U => u,
        Op::V => v,
        Op::Neg => -a,
        Op::Add => a + b,
        Op::Sub => a - b,
        Op::Mul => a * b,
        Op::Div => a / b,
        Op::PowI(n) => a.int_power(n),
        Op::PowF(k) => a.real_power(k),
        Op::Pow => a.power(b),
        Op::Call(f) if f.arity() == 1 => T::call1(f, a),
        Op::Call(f) => T::call2(f, a, b),
    }
}

/// A stack this deep lives on the machine stack; deeper programs allocate.
const SMALL_STACK: usize = 24;

impl Program {
    /// The formula's value at (u, v).
    pub(super) fn run<T: Number>(&self, u: T, v: T) -> T {
        let mut sp = 0;
        if self.depth <= SMALL_STACK {
            let mut s = [T::constant(0.0); SMALL_STACK];
            for op in &self.ops {
                exec(*op, &mut s, &mut sp, u, v);
            }
            s[0]
        } else {
            let mut s = vec![T::constant(0.0); self.depth];
            for op in &self.ops {
                exec(*op, &mut s, &mut sp, u, v);
            }
            s[0]
        }
    }

    /// What went wrong at (u, v): the first instruction whose value (or, with
    /// `derivatives`, whose derivatives) is not finite, said in words.
    pub(super) fn first_failure(&self, u: f64, v: f64, derivatives: bool) -> Option<String> {
        let mut s = vec![Jet::constant(0.0); self.depth.max(1)];
        let mut sp = 0;
        let (ju, jv) = (Jet::u(u), Jet::v(v));
        for (op, span) in self.ops.iter().zip(&self.spans) {
            let inputs: Vec<f64> = s[sp - op.arity()..sp].iter().map(|j| j.v).collect();
            exec(*op, &mut s, &mut sp, ju, jv);
            let j = s[sp - 1];
            let bad = if derivatives {
                ![j.du, j.dv, j.duu, j.duv, j.dvv]
                    .iter()
                    .all(|d| d.is_finite())
            } else {
                !j.v.is_finite()
            };
            if bad {
                let snippet: String = self.text[span.0..span.1].iter().collect();
                return Some(if derivatives {
                    format!(
                        "`{}` is {} there but its derivatives are not finite (it is not differentiable there)",
                        shorten(&snippet),
                        j.v
                    )
                } else {
                    failure(*op, &inputs, j.v, &snippet)
                });
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::super::Formula;
    use super::super::compiler::{Op, Program};
    use super::super::tests::{params, value};
    use crate::surfaces::Parametric;
    use std::f64::consts::PI;

    #[test]
    fn formulas_evaluate_to_their_values() {
        let cases: &[(&str, f64)] = &[
            ("1 + 2*3", 7.0),
            ("(1 + 2)*3", 9.0),
            ("2^3^2", 512.0),
            ("-2^2", -4.0),
            ("(-2)^2", 4.0),
            ("(-2)^3", -8.0),
            ("2^-1", 0.5),
            ("-u^2", -9.0),
            ("u^3", 27.0),
            ("+u - -v", 5.0),
            (".5e1 + 1e-3 + 2.5", 7.501),
            ("10/4/5", 0.5),
            ("8 - 2 - 1", 5.0),
            ("pi", PI),
            ("log(e)", 1.0),
            ("atan2(1, -1)", 0.75 * PI),
            ("min(u, v) + max(u, v)", 5.0),
            ("abs(v - u)", 1.0),
            ("sqrt(u + 1)^2", 4.0),
            ("2*a + alfa_2", 6.0),
            ("u^v", 9.0),
            ("u^0.5", 3f64.sqrt()),
            (
                "exp(0) + cosh(0) + sinh(0) + tanh(0) + tan(0) + asin(0) + acos(1) + atan(0)",
                2.0,
            ),
        ];
        for (text, want) in cases {
            let got = value(text, 3.0, 2.0, &[("a", 1.5), ("alfa_2", 3.0)]);
            assert!(
                (got - want).abs() <= 1e-15 * want.abs().max(1.0),
                "{text} = {got}, expected {want}"
            );
        }
        // Negative bases with a constant integer power work at run time too.
        assert_eq!(value("u^3 + u^-2", -2.0, 0.0, &[]), -8.0 + 0.25);
        assert_eq!(value("u^n", -2.0, 0.0, &[("n", 3.0)]), -8.0);
        // Constant parts are folded into one number.
        let p = Program::compile("2*pi*a + u", &params(&[("a", 0.5)]))
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(p.ops, vec![Op::Const(PI), Op::U, Op::Add]);
    }

    #[test]
    fn enclosures_hold_every_point_of_their_boxes() {
        use crate::surfaces::Interval;
        let texts = [
            "sin(3*u) * cos(v) + u^2",
            "exp(u - v) / (2 + cosh(v))",
            "log(1 + u^2) * tan(v/4)",
            "sqrt(u^2 + 1) - atan(u*v)",
            "asin(v/3) + acos(u/4)",
            "sinh(u) * tanh(v) + abs(u - v)",
            "atan2(v + 5, u) + min(u, v) * max(u, v)",
            "(u^2 + 1)^0.5 * (v^2 + 2)^v",
            "u^3 - 1/(u^2 + 0.1) * v",
        ];
        // A number in [0, 1) from an index.
        let unit = |i: u64| {
            let z = (i + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
            ((z ^ (z >> 29)).wrapping_mul(0xBF58_476D_1CE4_E5B9) >> 11) as f64 / (1u64 << 53) as f64
        };
        for text in texts {
            let p = Program::compile(text, &params(&[])).unwrap_or_else(|e| panic!("{e}"));
            for k in 0..60u64 {
                // Boxes from a point to a third of the range, within u, v in [-2.9, 2.9].
                let size = [0.0, 1e-6, 1e-3, 0.1, 1.0, 2.0][k as usize % 6];
                let u0 = -2.9 + (5.8 - size) * unit(4 * k);
                let v0 = -2.9 + (5.8 - size) * unit(4 * k + 1);
                let (u, v) = (Interval::new(u0, u0 + size), Interval::new(v0, v0 + size));
                let y = p.run(u, v);
                for i in 0..=8 {
                    for j in 0..=8 {
                        let (a, b) = (u0 + size * i as f64 / 8.0, v0 + size * j as f64 / 8.0);
                        let (a, b) = (a.min(u.hi()), b.min(v.hi()));
                        let x = p.run(a, b);
                        // The point's own rounding: a few units of its size.
                        let slack = 1e-12 * x.abs().max(1.0);
                        assert!(
                            y.lo() - slack <= x && x <= y.hi() + slack,
                            "{text} over u {u:?}, v {v:?} = {y:?} misses {x} at ({a}, {b})"
                        );
                    }
                }
                if size == 0.0 {
                    let x = p.run(u0, v0);
                    assert!(
                        y.width() <= 1e-12 * x.abs().max(1.0),
                        "{text}: {y:?} at a point"
                    );
                }
            }
        }
    }

    #[test]
    fn points_are_the_values_of_the_jets() {
        let f = Formula::example();
        for i in 0..50 {
            let (u, v) = (i as f64 * 0.13, i as f64 * 0.29);
            assert_eq!(f.point(0, u, v), f.eval(0, u, v).p);
        }
    }
}
