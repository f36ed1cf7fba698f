//! Complex curves in C^2 = R^4 (Hanson's Fermat surfaces and the product polynomial of
//! paper 000 section 5.3), drawn in coordinates (Re z1, Re z2, Im z1, Im z2).
//!
//! Each patch is holomorphic in ζ = u + i v, so its exact derivatives follow from f, f' and
//! f'' by the Cauchy-Riemann equations: ∂u f = f', ∂v f = i f', ∂uu f = f'', ∂uv f = i f'',
//! ∂vv f = -f''.

use super::{Domain, Eval4, Glue, Interval, Jet, Parametric, Scalar, Side, SideRule, Topology};
use crate::limits::{FERMAT_N, FERMAT_Y_RANGE, FieldError, PRODUCT_U_RANGE};
use glam::DVec4;
use num_complex::Complex64 as C64;
use serde::{Deserialize, Serialize};
use std::f64::consts::{FRAC_PI_2, TAU};
use std::ops::{Add, Div, Mul, Neg};

/// Real and imaginary part of a holomorphic function of ζ = u + iv as jets in (u, v), from
/// f, f' and f'' as (re, im) pairs.
fn holomorphic<S: Scalar>(f: [S; 2], f1: [S; 2], f2: [S; 2]) -> (Jet<S>, Jet<S>) {
    let re = Jet {
        v: f[0],
        du: f1[0],
        dv: -f1[1],
        duu: f2[0],
        duv: -f2[1],
        dvv: -f2[0],
    };
    let im = Jet {
        v: f[1],
        du: f1[1],
        dv: f1[0],
        duu: f2[1],
        duv: f2[0],
        dvv: -f2[1],
    };
    (re, im)
}

/// The jets of the point (Re z1, Re z2, Im z1, Im z2) from z1 and z2 with their first and
/// second derivatives in ζ.
fn jets<S: Scalar>(z1: [[S; 2]; 3], z2: [[S; 2]; 3]) -> [Jet<S>; 4] {
    let (r1, i1) = holomorphic(z1[0], z1[1], z1[2]);
    let (r2, i2) = holomorphic(z2[0], z2[1], z2[2]);
    [r1, r2, i1, i2]
}

/// Builds the point (Re z1, Re z2, Im z1, Im z2) from the jets of z1 and z2.
fn point(z1: (C64, C64, C64), z2: (C64, C64, C64)) -> Eval4 {
    let pair = |(a, b, c): (C64, C64, C64)| [a, b, c].map(|z| [z.re, z.im]);
    Eval4::from_jets(jets(pair(z1), pair(z2)))
}

/// A rectangle of complex numbers, for the enclosures: the arithmetic of [`Interval`]s on
/// the real and imaginary parts.
#[derive(Clone, Copy, Debug)]
struct Cx {
    re: Interval,
    im: Interval,
}

impl Cx {
    fn new(re: Interval, im: Interval) -> Cx {
        Cx { re, im }
    }

    /// e^{iθ}.
    fn unit(theta: Interval) -> Cx {
        let (sin, cos) = theta.sin_cos();
        Cx::new(cos, sin)
    }

    /// The exact e^{2πi k/n} enclosed, for n up to 6, made once.
    fn root(k: usize, n: usize) -> Cx {
        static ROOTS: std::sync::LazyLock<[[Cx; 6]; 7]> = std::sync::LazyLock::new(|| {
            std::array::from_fn(|n| {
                std::array::from_fn(|k| {
                    let turn = Interval::point(2.0 * k as f64) / Interval::point(n.max(1) as f64);
                    Cx::unit(Interval::PI * turn)
                })
            })
        });
        ROOTS[n][k % n]
    }

    fn pair(self) -> [Interval; 2] {
        [self.re, self.im]
    }

    fn entire() -> Cx {
        Cx::new(Interval::ENTIRE, Interval::ENTIRE)
    }

    /// The principal power g^p, 0 < p < 1, with its derivatives from g's: g^p is analytic
    /// where g stays off the negative real axis and 0 (the patches keep Re g >= 0). Where
    /// the rectangle of g holds 0, |g^p| <= |g|^p still bounds the value, and the
    /// derivatives are unbounded (a branch point).
    fn power(p: f64, g: Cx, g1: Cx, g2: Cx) -> [Cx; 3] {
        let norm2 = g.re.sqr() + g.im.sqr();
        if norm2.lo() <= 0.0 {
            let r = Interval::point(norm2.hi()).powf(p / 2.0).hi();
            let disc = Interval::new(-r, r);
            return [Cx::new(disc, disc), Cx::entire(), Cx::entire()];
        }
        let modulus = norm2.powf(p / 2.0);
        let h = Cx::unit(g.im.atan2(g.re) * Interval::point(p)) * modulus;
        let hm1 = h / g;
        let hm2 = hm1 / g;
        let p = Interval::point(p);
        [
            h,
            hm1 * g1 * p,
            hm2 * g1 * g1 * (p * (p - Interval::point(1.0))) + hm1 * g2 * p,
        ]
    }
}

impl Add for Cx {
    type Output = Cx;
    fn add(self, o: Cx) -> Cx {
        Cx::new(self.re + o.re, self.im + o.im)
    }
}

impl Neg for Cx {
    type Output = Cx;
    fn neg(self) -> Cx {
        Cx::new(-self.re, -self.im)
    }
}

impl Mul for Cx {
    type Output = Cx;
    fn mul(self, o: Cx) -> Cx {
        Cx::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
}

impl Mul<Interval> for Cx {
    type Output = Cx;
    fn mul(self, k: Interval) -> Cx {
        Cx::new(self.re * k, self.im * k)
    }
}

impl Div for Cx {
    type Output = Cx;
    fn div(self, o: Cx) -> Cx {
        let d = o.re.sqr() + o.im.sqr();
        Cx::new(
            (self.re * o.re + self.im * o.im) / d,
            (self.im * o.re - self.re * o.im) / d,
        )
    }
}

/// The enclosures' jets from the rectangles of z1 and z2 with their derivatives.
fn enclosure(z1: [Cx; 3], z2: [Cx; 3]) -> [Jet<Interval>; 4] {
    jets(z1.map(Cx::pair), z2.map(Cx::pair))
}

/// g^p with its first and second derivatives, given g, g', g'' (principal branch). Where
/// g = 0 and p < 2 the derivatives are infinite or NaN: a branch point of the patch.
fn power(p: f64, g: C64, g1: C64, g2: C64) -> (C64, C64, C64) {
    let h = if g == C64::new(0.0, 0.0) {
        g
    } else {
        g.powf(p)
    };
    let hm1 = h / g;
    let hm2 = hm1 / g;
    (
        h,
        hm1 * g1 * p,
        hm2 * g1 * g1 * (p * (p - 1.0)) + hm1 * g2 * p,
    )
}

/// e^{2πi k/n} for n up to 6, computed once.
fn unit_root(k: usize, n: usize) -> C64 {
    static ROOTS: std::sync::OnceLock<[[C64; 6]; 7]> = std::sync::OnceLock::new();
    let roots = ROOTS.get_or_init(|| {
        std::array::from_fn(|n| {
            std::array::from_fn(|k| C64::from_polar(1.0, TAU * k as f64 / n.max(1) as f64))
        })
    });
    roots[n][k % n]
}

/// Fermat surface z1^n + z2^n = 1 (Hanson): patch (k1, k2), k1, k2 in 0..n, is
/// z1 = e^{2πi k1/n} cos(ζ)^{2/n}, z2 = e^{2πi k2/n} sin(ζ)^{2/n}, ζ = x + iy,
/// x in [0, π/2], y in [-a, a]. Patch index k1 n + k2.
///
/// Seams, derived from the branch of the powers: on x = 0, the half y > 0 of patch (k1, k2)
/// is the half y < 0 of patch (k1, k2 + 1) at -y; on x = π/2, the half y > 0 of (k1, k2) is
/// the half y < 0 of (k1 - 1, k2) at -y. The points y = 0 on those sides (z2 = 0 and z1 = 0)
/// are shared by n patches each: branch points of the parametrization where the
/// derivatives are infinite for n > 2, although the surface is smooth there.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Fermat {
    /// The degree n, 2 to 6 (2: quadratic Fermat, 4: Calabi-Yau quartic cross-section).
    pub n: u32,
    /// Half-range a of the imaginary part y of ζ.
    pub y_range: f64,
}

impl Default for Fermat {
    fn default() -> Self {
        Fermat { n: 4, y_range: 1.0 }
    }
}

/// The principal square root (arg in (-π/2, π/2], the branch of `powf(0.5)`), computed
/// without cancellation on either side of the imaginary axis.
fn principal_sqrt(g: C64) -> C64 {
    let r = g.norm_sqr().sqrt();
    if r == 0.0 {
        return C64::new(0.0, 0.0);
    }
    if g.re >= 0.0 {
        let t = ((r + g.re) / 2.0).sqrt();
        C64::new(t, g.im / (2.0 * t))
    } else {
        let t = ((r - g.re) / 2.0).sqrt();
        C64::new(g.im.abs() / (2.0 * t), t.copysign(g.im))
    }
}

impl Fermat {
    fn patch_index(&self, k1: i64, k2: i64) -> usize {
        let n = self.n as i64;
        (k1.rem_euclid(n) * n + k2.rem_euclid(n)) as usize
    }
}

impl Fermat {
    /// cos ζ and sin ζ for ζ = u + iv, from one sincos and one exp.
    fn cos_sin(&self, u: f64, v: f64) -> (C64, C64) {
        let (sx, cx) = u.sin_cos();
        let e = v.exp();
        let (ch, sh) = ((e + 1.0 / e) / 2.0, (e - 1.0 / e) / 2.0);
        (C64::new(cx * ch, -sx * sh), C64::new(sx * ch, cx * sh))
    }
}

impl Parametric for Fermat {
    fn patch_count(&self) -> usize {
        (self.n * self.n) as usize
    }
    fn domain(&self, patch: usize) -> Domain {
        let n = self.n as i64;
        let (k1, k2) = (patch as i64 / n, patch as i64 % n);
        let half = |from: f64, patch: usize, side: Side| Glue {
            from,
            to: from + 0.5,
            patch,
            side,
            offset: 1.0,
            reversed: true,
        };
        let side = |lower: usize, upper: usize, side: Side| {
            SideRule::Glued(vec![half(0.0, lower, side), half(0.5, upper, side)])
        };
        Domain::open([0.0, FRAC_PI_2], [-self.y_range, self.y_range])
            .with(
                Side::U0,
                side(
                    self.patch_index(k1, k2 - 1),
                    self.patch_index(k1, k2 + 1),
                    Side::U0,
                ),
            )
            .with(
                Side::U1,
                side(
                    self.patch_index(k1 + 1, k2),
                    self.patch_index(k1 - 1, k2),
                    Side::U1,
                ),
            )
    }
    fn eval(&self, patch: usize, u: f64, v: f64) -> Eval4 {
        let n = self.n as usize;
        let (k1, k2) = (patch / n, patch % n);
        let p = 2.0 / self.n as f64;
        let (c, s) = self.cos_sin(u, v);
        let phase = |k: usize| unit_root(k, n);
        let scale = |(a, b, c): (C64, C64, C64), w: C64| (a * w, b * w, c * w);
        point(
            scale(power(p, c, -s, -c), phase(k1)),
            scale(power(p, s, c, -s), phase(k2)),
        )
    }
    /// The same closed forms over rectangles, with the exact roots of unity (π enclosed).
    fn enclose(&self, patch: usize, u: Interval, v: Interval) -> [Jet<Interval>; 4] {
        let n = self.n as usize;
        let (k1, k2) = (patch / n, patch % n);
        let (sin_u, cos_u) = u.sin_cos();
        let (sinh, cosh) = (v.sinh(), v.cosh());
        let c = Cx::new(cos_u * cosh, -(sin_u * sinh));
        let s = Cx::new(sin_u * cosh, cos_u * sinh);
        let power = |g: Cx, g1: Cx, g2: Cx| {
            if n == 2 {
                [g, g1, g2]
            } else {
                Cx::power(2.0 / n as f64, g, g1, g2)
            }
        };
        let turn = |z: [Cx; 3], k: usize| z.map(|z| z * Cx::root(k, n));
        enclosure(turn(power(c, -s, -c), k1), turn(power(s, c, -s), k2))
    }
    fn point(&self, patch: usize, u: f64, v: f64) -> DVec4 {
        let n = self.n as usize;
        let (k1, k2) = (patch / n, patch % n);
        let (c, s) = self.cos_sin(u, v);
        let p = 1.0 / self.n as f64;
        // g^(2/n) on the principal branch: g itself for n = 2, the principal square root for
        // n = 4 (no trigonometry), |g|^(2/n) e^{i (2/n) arg g} otherwise.
        let power = |g: C64| match self.n {
            2 => g,
            4 => principal_sqrt(g),
            _ => {
                let r = g.norm_sqr().powf(p);
                let (sin, cos) = (2.0 * p * g.arg()).sin_cos();
                C64::new(r * cos, r * sin)
            }
        };
        let z1 = power(c) * unit_root(k1, n);
        let z2 = power(s) * unit_root(k2, n);
        DVec4::new(z1.re, z2.re, z1.im, z2.im)
    }
    /// The affine curve z1^n + z2^n = 1 is a closed surface of genus (n - 1)(n - 2)/2
    /// without its n points at infinity; the strip keeps it but a disc around each:
    /// χ = 2 - (n - 1)(n - 2) - n = n (2 - n).
    fn topology(&self) -> Topology {
        let n = i64::from(self.n);
        Topology {
            closed: false,
            orientable: true,
            euler_characteristic: Some(n * (2 - n)),
        }
    }
    fn check(&self) -> Result<(), FieldError> {
        FERMAT_N.check("n", self.n)?;
        FERMAT_Y_RANGE.check_with(
            "y_range",
            self.y_range,
            "coordinates grow like e^(2a/n); a narrower strip is a sliver with nothing to show",
        )
    }
}

/// Product polynomial z1^2 z2^2 = 1, i.e. z1 z2 = ±1: two sheets (patch 0: +1, patch 1: -1),
/// each z1 = e^ζ, z2 = ±e^{-ζ} with ζ = u + iv, u in [-a, a], v in [0, 2π] periodic.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ProductPolynomial {
    /// Half-range a of u = log |z1|.
    pub u_range: f64,
}

impl Default for ProductPolynomial {
    fn default() -> Self {
        ProductPolynomial { u_range: 0.8 }
    }
}

impl Parametric for ProductPolynomial {
    fn patch_count(&self) -> usize {
        2
    }
    fn domain(&self, patch: usize) -> Domain {
        Domain::open([-self.u_range, self.u_range], [0.0, TAU]).glue_v(patch)
    }
    fn eval(&self, patch: usize, u: f64, v: f64) -> Eval4 {
        let e = C64::new(u, v).exp();
        let f = C64::new(-u, -v).exp() * if patch == 0 { 1.0 } else { -1.0 };
        point((e, e, e), (f, -f, f))
    }
    fn enclose(&self, patch: usize, u: Interval, v: Interval) -> [Jet<Interval>; 4] {
        let sign = Interval::point(if patch == 0 { 1.0 } else { -1.0 });
        let e = Cx::unit(v) * u.exp();
        let f = Cx::unit(-v) * ((-u).exp() * sign);
        enclosure([e, e, e], [f, -f, f])
    }
    /// Two annuli.
    fn topology(&self) -> Topology {
        Topology {
            closed: false,
            orientable: true,
            euler_characteristic: Some(0),
        }
    }
    fn check(&self) -> Result<(), FieldError> {
        PRODUCT_U_RANGE.check_with("u_range", self.u_range, "coordinates grow like e^a")
    }
}
