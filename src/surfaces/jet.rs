//! Second-order forward-mode automatic differentiation in two variables.
//!
//! A [`Jet`] carries a value together with its exact first and second partial derivatives
//! with respect to the surface parameters (u, v). Arithmetic and the elementary functions
//! propagate them by the chain rule, so every catalogue surface gets exact derivatives from
//! the same code that evaluates its points: no finite differences anywhere.
//!
//! A jet is written over a [`Scalar`]: `f64` (a point with its derivatives) or
//! [`Interval`] (a box of parameters, and enclosures of the point and of its derivatives
//! over the whole box, which the proven tolerance and the certified curves rest on). The
//! chain rule is the same for both; where a function has a kink or a jump (`abs`, `min`,
//! `max`, `atan2` across its cut), an interval jet whose box reaches it has unbounded
//! derivatives, since no bound holds there.

use super::Interval;
use std::fmt::Debug;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// The numbers a [`Jet`] is made of: `f64`, or [`Interval`] for enclosures over a box.
pub trait Scalar:
    Copy
    + Debug
    + PartialEq
    + From<f64>
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// sin and cos.
    fn sin_cos(self) -> (Self, Self);
    /// tan.
    fn tan(self) -> Self;
    /// asin.
    fn asin(self) -> Self;
    /// acos.
    fn acos(self) -> Self;
    /// atan.
    fn atan(self) -> Self;
    /// sinh.
    fn sinh(self) -> Self;
    /// cosh.
    fn cosh(self) -> Self;
    /// tanh.
    fn tanh(self) -> Self;
    /// e^x.
    fn exp(self) -> Self;
    /// The natural logarithm.
    fn ln(self) -> Self;
    /// The square root.
    fn sqrt(self) -> Self;
    /// An integer power.
    fn powi(self, n: i32) -> Self;
    /// A real power.
    fn powf(self, k: f64) -> Self;
}

/// [`Scalar`] for a type whose own methods of the same names do the work.
macro_rules! scalar {
    ($t:ty) => {
        impl Scalar for $t {
            fn sin_cos(self) -> (Self, Self) {
                <$t>::sin_cos(self)
            }
            scalar!(@unary $t: tan asin acos atan sinh cosh tanh exp ln sqrt);
            fn powi(self, n: i32) -> Self {
                <$t>::powi(self, n)
            }
            fn powf(self, k: f64) -> Self {
                <$t>::powf(self, k)
            }
        }
    };
    (@unary $t:ty: $($f:ident)*) => {
        $(fn $f(self) -> Self {
            <$t>::$f(self)
        })*
    };
}

// Each operation of f64 is its own, so that a jet's value is the same bits as the plain
// evaluation's; each of Interval's encloses its value.
scalar!(f64);
scalar!(Interval);

/// A value with its first and second partial derivatives in (u, v).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Jet<S = f64> {
    /// The value.
    pub v: S,
    /// ∂/∂u.
    pub du: S,
    /// ∂/∂v.
    pub dv: S,
    /// ∂²/∂u².
    pub duu: S,
    /// ∂²/∂u∂v.
    pub duv: S,
    /// ∂²/∂v².
    pub dvv: S,
}

impl<S: Scalar> Jet<S> {
    /// A constant: all derivatives zero.
    pub fn constant(v: S) -> Self {
        let z = S::from(0.0);
        Jet {
            v,
            du: z,
            dv: z,
            duu: z,
            duv: z,
            dvv: z,
        }
    }

    /// The parameter u itself.
    pub fn u(u: S) -> Self {
        Jet {
            du: S::from(1.0),
            ..Jet::constant(u)
        }
    }

    /// The parameter v itself.
    pub fn v(v: S) -> Self {
        Jet {
            dv: S::from(1.0),
            ..Jet::constant(v)
        }
    }

    /// A value with unbounded derivatives: what a function with a kink or a jump inside an
    /// interval jet's box gives.
    fn unbounded(v: S, entire: S) -> Self {
        Jet {
            v,
            du: entire,
            dv: entire,
            duu: entire,
            duv: entire,
            dvv: entire,
        }
    }

    /// Applies a scalar function with value `f`, derivative `f1` and second derivative `f2`
    /// (all taken at `self.v`) by the chain rule.
    pub fn chain(self, f: S, f1: S, f2: S) -> Self {
        Jet {
            v: f,
            du: f1 * self.du,
            dv: f1 * self.dv,
            duu: f2 * self.du * self.du + f1 * self.duu,
            duv: f2 * self.du * self.dv + f1 * self.duv,
            dvv: f2 * self.dv * self.dv + f1 * self.dvv,
        }
    }

    /// sin.
    pub fn sin(self) -> Self {
        let (s, c) = self.v.sin_cos();
        self.chain(s, c, -s)
    }

    /// cos.
    pub fn cos(self) -> Self {
        let (s, c) = self.v.sin_cos();
        self.chain(c, -s, -c)
    }

    /// Square.
    pub fn sqr(self) -> Self {
        self * self
    }

    /// Cube.
    pub fn cube(self) -> Self {
        self * self * self
    }

    /// Multiplies by a constant.
    pub fn scale(self, k: f64) -> Self {
        let k = S::from(k);
        Jet {
            v: k * self.v,
            du: k * self.du,
            dv: k * self.dv,
            duu: k * self.duu,
            duv: k * self.duv,
            dvv: k * self.dvv,
        }
    }

    /// Divides by a constant.
    pub fn over(self, k: f64) -> Self {
        let k = S::from(k);
        Jet {
            v: self.v / k,
            du: self.du / k,
            dv: self.dv / k,
            duu: self.duu / k,
            duv: self.duv / k,
            dvv: self.dvv / k,
        }
    }

    /// Reciprocal 1 / x.
    pub fn recip(self) -> Self {
        let r = S::from(1.0) / self.v;
        self.chain(r, -r * r, S::from(2.0) * r * r * r)
    }

    /// Applies a function of two variables `f(self, o)` with value `f`, gradient `g` and
    /// Hessian `h = [f_aa, f_ab, f_bb]` (taken at `(self.v, o.v)`) by the chain rule.
    pub fn chain2(self, o: Jet<S>, f: S, g: [S; 2], h: [S; 3]) -> Self {
        let (a, b) = (self, o);
        let second = |ai: S, aj: S, bi: S, bj: S, aij: S, bij: S| {
            h[0] * ai * aj + h[1] * (ai * bj + bi * aj) + h[2] * bi * bj + g[0] * aij + g[1] * bij
        };
        Jet {
            v: f,
            du: g[0] * a.du + g[1] * b.du,
            dv: g[0] * a.dv + g[1] * b.dv,
            duu: second(a.du, a.du, b.du, b.du, a.duu, b.duu),
            duv: second(a.du, a.dv, b.du, b.dv, a.duv, b.duv),
            dvv: second(a.dv, a.dv, b.dv, b.dv, a.dvv, b.dvv),
        }
    }

    /// tan.
    pub fn tan(self) -> Self {
        let t = self.v.tan();
        let d = S::from(1.0) + t * t;
        self.chain(t, d, S::from(2.0) * t * d)
    }

    /// asin (NaN outside [-1, 1], infinite derivatives at ±1).
    pub fn asin(self) -> Self {
        let x = self.v;
        let q = S::from(1.0) - x * x;
        let d = S::from(1.0) / q.sqrt();
        self.chain(x.asin(), d, x * d / q)
    }

    /// acos (NaN outside [-1, 1], infinite derivatives at ±1).
    pub fn acos(self) -> Self {
        let x = self.v;
        let q = S::from(1.0) - x * x;
        let d = S::from(1.0) / q.sqrt();
        self.chain(x.acos(), -d, -x * d / q)
    }

    /// atan.
    pub fn atan(self) -> Self {
        let x = self.v;
        let d = S::from(1.0) / (S::from(1.0) + x * x);
        self.chain(x.atan(), d, S::from(-2.0) * x * d * d)
    }

    /// The derivatives of the angle of (x, y) = (`x`, `self`) applied to `angle`, its
    /// value.
    fn angle(self, x: Jet<S>, angle: S) -> Self {
        let (a, b) = (self.v, x.v);
        let r2 = a * a + b * b;
        let q = S::from(1.0) / (r2 * r2);
        let two = S::from(2.0);
        self.chain2(
            x,
            angle,
            [b / r2, -a / r2],
            [-two * a * b * q, (a * a - b * b) * q, two * a * b * q],
        )
    }

    /// sinh.
    pub fn sinh(self) -> Self {
        let (s, c) = (self.v.sinh(), self.v.cosh());
        self.chain(s, c, s)
    }

    /// cosh.
    pub fn cosh(self) -> Self {
        let (s, c) = (self.v.sinh(), self.v.cosh());
        self.chain(c, s, c)
    }

    /// tanh.
    pub fn tanh(self) -> Self {
        let t = self.v.tanh();
        let d = S::from(1.0) - t * t;
        self.chain(t, d, S::from(-2.0) * t * d)
    }

    /// exp.
    pub fn exp(self) -> Self {
        let e = self.v.exp();
        self.chain(e, e, e)
    }

    /// The natural logarithm (NaN for negative numbers, -∞ at 0).
    pub fn ln(self) -> Self {
        let r = S::from(1.0) / self.v;
        self.chain(self.v.ln(), r, -r * r)
    }

    /// Square root (NaN for negative numbers, infinite derivatives at 0).
    pub fn sqrt(self) -> Self {
        let s = self.v.sqrt();
        let d = S::from(0.5) / s;
        self.chain(s, d, S::from(-0.5) * d / self.v)
    }

    /// An integer power (any base, negative ones included; 0 to a negative power is
    /// infinite).
    pub fn powi(self, n: i32) -> Self {
        let x = self.v;
        let k = f64::from(n);
        // A zero coefficient stays zero where the power beside it is infinite (x^1 at 0).
        let term = |c: f64, e: i32| {
            if c == 0.0 {
                S::from(0.0)
            } else {
                S::from(c) * x.powi(e)
            }
        };
        self.chain(
            x.powi(n),
            term(k, n.saturating_sub(1)),
            term(k * (k - 1.0), n.saturating_sub(2)),
        )
    }

    /// A constant real power x^k (NaN for negative x unless k is an integer: use
    /// [`Jet::powi`] for those).
    pub fn powf(self, k: f64) -> Self {
        let x = self.v;
        let term = |c: f64, e: f64| {
            if c == 0.0 {
                S::from(0.0)
            } else {
                S::from(c) * x.powf(e)
            }
        };
        self.chain(x.powf(k), term(k, k - 1.0), term(k * (k - 1.0), k - 2.0))
    }

    /// A power with a varying exponent, exp(y ln x): defined for positive bases.
    pub fn pow(self, y: Jet<S>) -> Self {
        (y * self.ln()).exp()
    }
}

impl Jet<f64> {
    /// The angle of the point (x, y) = (`x`, `self`), in (-π, π], as `f64::atan2`. Its
    /// derivatives are those of the angle, smooth away from the origin (the jump across the
    /// negative x axis is not seen by derivatives).
    pub fn atan2(self, x: Jet) -> Self {
        self.angle(x, self.v.atan2(x.v))
    }

    /// Absolute value; at 0 the derivatives are those of the identity (one-sided).
    pub fn abs(self) -> Self {
        if self.v < 0.0 { -self } else { self }
    }

    /// The jet of the smaller value (the first on a tie).
    pub fn min(self, o: Jet) -> Self {
        if o.v < self.v { o } else { self }
    }

    /// The jet of the larger value (the first on a tie).
    pub fn max(self, o: Jet) -> Self {
        if o.v > self.v { o } else { self }
    }
}

/// Over a box, the functions with a kink or a jump keep their derivatives only where the
/// box stays on one side of it.
impl Jet<Interval> {
    /// The angle of (x, y) = (`x`, `self`): unbounded derivatives where the box of (x, y)
    /// reaches the origin or the cut along the negative x axis, where the angle jumps.
    pub fn atan2(self, x: Jet<Interval>) -> Self {
        let angle = self.v.atan2(x.v);
        if x.v.lo() > 0.0 || !self.v.contains(0.0) {
            self.angle(x, angle)
        } else {
            Jet::unbounded(angle, Interval::ENTIRE)
        }
    }

    /// |x|: unbounded derivatives where the box holds a point where x changes sign.
    pub fn abs(self) -> Self {
        if self.v.lo() >= 0.0 {
            self
        } else if self.v.hi() <= 0.0 {
            -self
        } else {
            Jet::unbounded(self.v.abs(), Interval::ENTIRE)
        }
    }

    /// The smaller: unbounded derivatives where either may be the smaller.
    pub fn min(self, o: Jet<Interval>) -> Self {
        if self.v.hi() <= o.v.lo() {
            self
        } else if o.v.hi() <= self.v.lo() {
            o
        } else {
            Jet::unbounded(self.v.min(o.v), Interval::ENTIRE)
        }
    }

    /// The larger: unbounded derivatives where either may be the larger.
    pub fn max(self, o: Jet<Interval>) -> Self {
        if self.v.lo() >= o.v.hi() {
            self
        } else if o.v.lo() >= self.v.hi() {
            o
        } else {
            Jet::unbounded(self.v.max(o.v), Interval::ENTIRE)
        }
    }

    /// The least jet holding both (each part the hull of the two).
    pub fn union(self, o: Jet<Interval>) -> Self {
        Jet {
            v: self.v.union(o.v),
            du: self.du.union(o.du),
            dv: self.dv.union(o.dv),
            duu: self.duu.union(o.duu),
            duv: self.duv.union(o.duv),
            dvv: self.dvv.union(o.dvv),
        }
    }
}

/// The numbers a surface's formula is written over once and evaluated in several ways: as
/// plain values (`f64`, for a point alone, which the samplers and the audit ask for
/// millions of times), as [`Jet`]s (for a point with its derivatives) and as jets of
/// intervals (enclosures over a box). Each operation computes the value the same way in
/// the first two, so a point is the same bits either way.
pub trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Neg<Output = Self>
    + Add<f64, Output = Self>
    + Sub<f64, Output = Self>
    + Mul<f64, Output = Self>
{
    /// A constant.
    fn constant(v: f64) -> Self;
    /// sin and cos, from one evaluation.
    fn sin_cos(self) -> (Self, Self);
    /// Square.
    fn sqr(self) -> Self;
    /// Cube.
    fn cube(self) -> Self;
}

impl Real for f64 {
    fn constant(v: f64) -> Self {
        v
    }
    fn sin_cos(self) -> (Self, Self) {
        f64::sin_cos(self)
    }
    fn sqr(self) -> Self {
        self * self
    }
    fn cube(self) -> Self {
        self * self * self
    }
}

impl<S: Scalar> Real for Jet<S> {
    fn constant(v: f64) -> Self {
        Jet::constant(S::from(v))
    }
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = self.v.sin_cos();
        (self.chain(s, c, -s), self.chain(c, -s, -c))
    }
    fn sqr(self) -> Self {
        Jet::sqr(self)
    }
    fn cube(self) -> Self {
        Jet::cube(self)
    }
}

impl<S: Scalar> From<f64> for Jet<S> {
    fn from(v: f64) -> Self {
        Jet::constant(S::from(v))
    }
}

impl<S: Scalar> Add for Jet<S> {
    type Output = Jet<S>;
    fn add(self, o: Jet<S>) -> Jet<S> {
        Jet {
            v: self.v + o.v,
            du: self.du + o.du,
            dv: self.dv + o.dv,
            duu: self.duu + o.duu,
            duv: self.duv + o.duv,
            dvv: self.dvv + o.dvv,
        }
    }
}

impl<S: Scalar> Sub for Jet<S> {
    type Output = Jet<S>;
    fn sub(self, o: Jet<S>) -> Jet<S> {
        self + (-o)
    }
}

impl<S: Scalar> Neg for Jet<S> {
    type Output = Jet<S>;
    fn neg(self) -> Jet<S> {
        self.scale(-1.0)
    }
}

impl<S: Scalar> Mul for Jet<S> {
    type Output = Jet<S>;
    fn mul(self, o: Jet<S>) -> Jet<S> {
        let two = S::from(2.0);
        Jet {
            v: self.v * o.v,
            du: self.du * o.v + self.v * o.du,
            dv: self.dv * o.v + self.v * o.dv,
            duu: self.duu * o.v + two * self.du * o.du + self.v * o.duu,
            duv: self.duv * o.v + self.du * o.dv + self.dv * o.du + self.v * o.duv,
            dvv: self.dvv * o.v + two * self.dv * o.dv + self.v * o.dvv,
        }
    }
}

impl<S: Scalar> Div for Jet<S> {
    type Output = Jet<S>;
    #[allow(clippy::suspicious_arithmetic_impl)]
    fn div(self, o: Jet<S>) -> Jet<S> {
        self * o.recip()
    }
}

impl<S: Scalar> Add<f64> for Jet<S> {
    type Output = Jet<S>;
    fn add(mut self, k: f64) -> Jet<S> {
        self.v = self.v + S::from(k);
        self
    }
}

impl<S: Scalar> Sub<f64> for Jet<S> {
    type Output = Jet<S>;
    fn sub(mut self, k: f64) -> Jet<S> {
        self.v = self.v - S::from(k);
        self
    }
}

impl<S: Scalar> Mul<f64> for Jet<S> {
    type Output = Jet<S>;
    fn mul(self, k: f64) -> Jet<S> {
        self.scale(k)
    }
}

impl<S: Scalar> Add<Jet<S>> for f64 {
    type Output = Jet<S>;
    fn add(self, j: Jet<S>) -> Jet<S> {
        j + self
    }
}

impl<S: Scalar> Sub<Jet<S>> for f64 {
    type Output = Jet<S>;
    fn sub(self, j: Jet<S>) -> Jet<S> {
        -j + self
    }
}

impl<S: Scalar> Mul<Jet<S>> for f64 {
    type Output = Jet<S>;
    fn mul(self, j: Jet<S>) -> Jet<S> {
        j.scale(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn product_rule_on_polynomial() {
        // f = u^2 v^3 at (2, 3): f_u = 2uv^3 = 108, f_v = 3u^2v^2 = 108,
        // f_uu = 2v^3 = 54, f_uv = 6uv^2 = 108, f_vv = 6u^2v = 72.
        let (u, v) = (Jet::u(2.0), Jet::v(3.0));
        let f = u.sqr() * v.cube();
        assert_eq!((f.v, f.du, f.dv), (108.0, 108.0, 108.0));
        assert_eq!((f.duu, f.duv, f.dvv), (54.0, 108.0, 72.0));
    }

    /// Checks a one-variable function's jet at `x` (taken as u) against its closed-form
    /// value and first two derivatives.
    fn against(name: &str, f: fn(Jet) -> Jet, x: f64, exact: [f64; 3]) {
        let j = f(Jet::u(x));
        for (k, (got, want)) in [j.v, j.du, j.duu].into_iter().zip(exact).enumerate() {
            assert!(
                (got - want).abs() <= 1e-14 * want.abs().max(1.0),
                "{name} at {x}: derivative {k} is {got}, expected {want}"
            );
        }
        assert_eq!((j.dv, j.duv, j.dvv), (0.0, 0.0, 0.0), "{name}");
    }

    #[test]
    fn elementary_functions_against_closed_forms() {
        let x = 0.3f64;
        let c = x.cos();
        against(
            "tan",
            Jet::tan,
            x,
            [x.tan(), 1.0 / (c * c), 2.0 * x.sin() / (c * c * c)],
        );
        let q = 1.0 - x * x;
        against(
            "asin",
            Jet::asin,
            x,
            [x.asin(), q.powf(-0.5), x * q.powf(-1.5)],
        );
        against(
            "acos",
            Jet::acos,
            x,
            [x.acos(), -q.powf(-0.5), -x * q.powf(-1.5)],
        );
        let p = 1.0 + x * x;
        against(
            "atan",
            Jet::atan,
            x,
            [x.atan(), 1.0 / p, -2.0 * x / (p * p)],
        );
        against("sinh", Jet::sinh, x, [x.sinh(), x.cosh(), x.sinh()]);
        against("cosh", Jet::cosh, x, [x.cosh(), x.sinh(), x.cosh()]);
        let s2 = 1.0 / (x.cosh() * x.cosh());
        against("tanh", Jet::tanh, x, [x.tanh(), s2, -2.0 * x.tanh() * s2]);
        against("exp", Jet::exp, x, [x.exp(), x.exp(), x.exp()]);
        against("ln", Jet::ln, x, [x.ln(), 1.0 / x, -1.0 / (x * x)]);
        against(
            "sqrt",
            Jet::sqrt,
            x,
            [x.sqrt(), 0.5 / x.sqrt(), -0.25 * x.powf(-1.5)],
        );
        against("abs", Jet::<f64>::abs, -x, [x, -1.0, 0.0]);
        against("abs", Jet::<f64>::abs, x, [x, 1.0, 0.0]);
        against(
            "powi",
            |j| j.powi(3),
            -x,
            [-x * x * x, 3.0 * x * x, -6.0 * x],
        );
        against(
            "powi",
            |j| j.powi(-2),
            -x,
            [1.0 / (x * x), 2.0 / (x * x * x), 6.0 / x.powi(4)],
        );
        against("powi", |j| j.powi(1), 0.0, [0.0, 1.0, 0.0]);
        against("powi", |j| j.powi(0), 0.0, [1.0, 0.0, 0.0]);
        against(
            "powf",
            |j| j.powf(2.5),
            x,
            [x.powf(2.5), 2.5 * x.powf(1.5), 3.75 * x.sqrt()],
        );
        against("powf", |j| j.powf(1.0), 0.0, [0.0, 1.0, 0.0]);
        // x^x = exp(x ln x): (x^x)' = x^x (ln x + 1), (x^x)'' = x^x ((ln x + 1)^2 + 1/x).
        let l = x.ln() + 1.0;
        let xx = x.powf(x);
        against("pow", |j| j.pow(j), x, [xx, xx * l, xx * (l * l + 1.0 / x)]);
    }

    #[test]
    fn two_argument_functions_follow_both_jets() {
        // atan2(v, u) is the polar angle: derivatives -v/r², u/r², 2uv/r⁴, (v²-u²)/r⁴,
        // -2uv/r⁴.
        let (u, v) = (0.7f64, -0.4f64);
        let a = Jet::v(v).atan2(Jet::u(u));
        let r2 = u * u + v * v;
        let q = r2 * r2;
        let want = [
            v.atan2(u),
            -v / r2,
            u / r2,
            2.0 * u * v / q,
            (v * v - u * u) / q,
            -2.0 * u * v / q,
        ];
        let got = [a.v, a.du, a.dv, a.duu, a.duv, a.dvv];
        for (g, w) in got.iter().zip(want) {
            assert!((g - w).abs() < 1e-14, "{got:?} against {want:?}");
        }
        // u^v = exp(v ln u): d/du = v u^(v-1), d/dv = u^v ln u, d²/du dv = u^(v-1) (1 + v ln u).
        let p = Jet::u(u).pow(Jet::v(v));
        let l = u.ln();
        let want = [
            u.powf(v),
            v * u.powf(v - 1.0),
            u.powf(v) * l,
            v * (v - 1.0) * u.powf(v - 2.0),
            u.powf(v - 1.0) * (1.0 + v * l),
            u.powf(v) * l * l,
        ];
        let got = [p.v, p.du, p.dv, p.duu, p.duv, p.dvv];
        for (g, w) in got.iter().zip(want) {
            assert!((g - w).abs() < 1e-14, "{got:?} against {want:?}");
        }
        // min and max keep the whole jet of the chosen argument.
        let (a, b) = (Jet::u(1.0), Jet::v(2.0));
        assert_eq!(a.min(b), a);
        assert_eq!(a.max(b), b);
        assert_eq!(b.min(a), a);
    }

    #[test]
    fn quotient_and_trig() {
        // f = sin(u) / v at (0.5, 2).
        let (u, v) = (Jet::u(0.5), Jet::v(2.0));
        let f = u.sin() / v;
        let (s, c) = 0.5f64.sin_cos();
        let close = |a: f64, b: f64| (a - b).abs() < 1e-15;
        assert!(close(f.du, c / 2.0));
        assert!(close(f.dv, -s / 4.0));
        assert!(close(f.duu, -s / 2.0));
        assert!(close(f.duv, -c / 4.0));
        assert!(close(f.dvv, 2.0 * s / 8.0));
    }

    #[test]
    fn interval_jets_lose_their_derivatives_only_across_a_kink() {
        let x = |lo: f64, hi: f64| Jet::u(Interval::new(lo, hi));
        let y = |lo: f64, hi: f64| Jet::v(Interval::new(lo, hi));
        // On one side: the identity's jet (or its negative), exactly.
        assert_eq!(x(0.0, 1.0).abs(), x(0.0, 1.0));
        assert_eq!(x(-1.0, -0.5).abs(), -x(-1.0, -0.5));
        assert_eq!(x(0.0, 1.0).min(y(2.0, 3.0)), x(0.0, 1.0));
        assert_eq!(x(0.0, 1.0).max(y(2.0, 3.0)), y(2.0, 3.0));
        assert!(x(1.0, 2.0).atan2(y(1.0, 2.0)).duu.is_bounded());
        // Across: the value still enclosed, the derivatives unbounded.
        let across = [
            x(-1.0, 1.0).abs(),
            x(0.0, 1.0).min(y(0.5, 3.0)),
            x(0.0, 1.0).max(y(0.5, 3.0)),
            // The angle of (x, y) = (-1, [-0.1, 0.1]) jumps across its cut.
            y(-0.1, 0.1).atan2(Jet::constant(Interval::point(-1.0))),
        ];
        for j in across {
            assert!(
                j.v.is_bounded() && !j.du.is_bounded() && !j.duu.is_bounded(),
                "{j:?}"
            );
        }
    }
}
