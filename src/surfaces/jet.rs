//! Second-order forward-mode automatic differentiation in two variables.
//!
//! A [`Jet`] carries a value together with its exact first and second partial derivatives
//! with respect to the surface parameters (u, v). Arithmetic and the elementary functions
//! propagate them by the chain rule, so every catalogue surface gets exact derivatives from
//! the same code that evaluates its points: no finite differences anywhere.

use std::ops::{Add, Div, Mul, Neg, Sub};

/// A value with its first and second partial derivatives in (u, v).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Jet {
    /// The value.
    pub v: f64,
    /// ∂/∂u.
    pub du: f64,
    /// ∂/∂v.
    pub dv: f64,
    /// ∂²/∂u².
    pub duu: f64,
    /// ∂²/∂u∂v.
    pub duv: f64,
    /// ∂²/∂v².
    pub dvv: f64,
}

impl Jet {
    /// A constant: all derivatives zero.
    pub const fn constant(v: f64) -> Self {
        Jet {
            v,
            du: 0.0,
            dv: 0.0,
            duu: 0.0,
            duv: 0.0,
            dvv: 0.0,
        }
    }

    /// The parameter u itself.
    pub const fn u(u: f64) -> Self {
        Jet {
            v: u,
            du: 1.0,
            dv: 0.0,
            duu: 0.0,
            duv: 0.0,
            dvv: 0.0,
        }
    }

    /// The parameter v itself.
    pub const fn v(v: f64) -> Self {
        Jet {
            v,
            du: 0.0,
            dv: 1.0,
            duu: 0.0,
            duv: 0.0,
            dvv: 0.0,
        }
    }

    /// Applies a scalar function with value `f`, derivative `f1` and second derivative `f2`
    /// (all taken at `self.v`) by the chain rule.
    pub fn chain(self, f: f64, f1: f64, f2: f64) -> Self {
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
        Jet {
            v: k * self.v,
            du: k * self.du,
            dv: k * self.dv,
            duu: k * self.duu,
            duv: k * self.duv,
            dvv: k * self.dvv,
        }
    }

    /// Reciprocal 1 / x.
    pub fn recip(self) -> Self {
        let r = 1.0 / self.v;
        self.chain(r, -r * r, 2.0 * r * r * r)
    }
}

impl From<f64> for Jet {
    fn from(v: f64) -> Self {
        Jet::constant(v)
    }
}

impl Add for Jet {
    type Output = Jet;
    fn add(self, o: Jet) -> Jet {
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

impl Sub for Jet {
    type Output = Jet;
    fn sub(self, o: Jet) -> Jet {
        self + (-o)
    }
}

impl Neg for Jet {
    type Output = Jet;
    fn neg(self) -> Jet {
        self.scale(-1.0)
    }
}

impl Mul for Jet {
    type Output = Jet;
    fn mul(self, o: Jet) -> Jet {
        Jet {
            v: self.v * o.v,
            du: self.du * o.v + self.v * o.du,
            dv: self.dv * o.v + self.v * o.dv,
            duu: self.duu * o.v + 2.0 * self.du * o.du + self.v * o.duu,
            duv: self.duv * o.v + self.du * o.dv + self.dv * o.du + self.v * o.duv,
            dvv: self.dvv * o.v + 2.0 * self.dv * o.dv + self.v * o.dvv,
        }
    }
}

impl Div for Jet {
    type Output = Jet;
    #[allow(clippy::suspicious_arithmetic_impl)]
    fn div(self, o: Jet) -> Jet {
        self * o.recip()
    }
}

impl Add<f64> for Jet {
    type Output = Jet;
    fn add(mut self, k: f64) -> Jet {
        self.v += k;
        self
    }
}

impl Sub<f64> for Jet {
    type Output = Jet;
    fn sub(mut self, k: f64) -> Jet {
        self.v -= k;
        self
    }
}

impl Mul<f64> for Jet {
    type Output = Jet;
    fn mul(self, k: f64) -> Jet {
        self.scale(k)
    }
}

impl Add<Jet> for f64 {
    type Output = Jet;
    fn add(self, j: Jet) -> Jet {
        j + self
    }
}

impl Sub<Jet> for f64 {
    type Output = Jet;
    fn sub(self, j: Jet) -> Jet {
        -j + self
    }
}

impl Mul<Jet> for f64 {
    type Output = Jet;
    fn mul(self, j: Jet) -> Jet {
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
}
