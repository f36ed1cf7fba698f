//! Intervals of f64 with outward rounding: enclosures that hold the true value of every
//! operation on every point of its operands' intervals, whatever the rounding did.
//!
//! Each basic operation (+, -, *, /, square root) is rounded to nearest by the hardware,
//! which IEEE 754 guarantees to be within half a unit in the last place of the true result,
//! and its bounds are then moved one unit outward (`next_down`, `next_up`): the true result
//! lies inside. The elementary functions are not taken from the platform's `libm`, whose
//! error is measured, not proven: each is reduced to a small argument and summed as its
//! Taylor series in interval arithmetic, with the series' remainder (Lagrange's bound, or the
//! alternating series' next term) added as an interval, so that their enclosures rest on
//! the basic operations alone. Where a function is undefined on part of an interval (the
//! logarithm of an interval that reaches 0, a division by an interval holding 0), the result
//! is the whole line ([`Interval::ENTIRE`]): a bound that proves nothing, never a wrong one.
//!
//! Why by hand: `inari`, the Rust crate that implements IEEE 1788, takes its elementary
//! functions from MPFR, and building `gmp-mpfr-sys` needs `m4` and a C toolchain that a
//! fresh machine does not have (`cargo build` fails there); without that feature it has no
//! elementary functions at all.

use std::f64::consts::{FRAC_PI_2, LN_2};
use std::ops::{Add, Div, Mul, Neg, Sub};

/// A closed interval [lo, hi] of reals, lo <= hi; infinite bounds are allowed, NaN never.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    lo: f64,
    hi: f64,
}

/// The largest f64 below x (x itself at -infinity).
#[inline]
fn down(x: f64) -> f64 {
    x.next_down()
}

/// The smallest f64 above x (x itself at +infinity).
#[inline]
fn up(x: f64) -> f64 {
    x.next_up()
}

/// ln 2: the nearest f64 is below it (0x3FE62E42FEFA39EF = 0.693147180559945286...,
/// ln 2 = 0.693147180559945309...).
const LN2: Interval = Interval {
    lo: LN_2,
    hi: 0.693_147_180_559_945_4,
};

/// π/2: the nearest f64 is below it (0x3FF921FB54442D18 = 1.570796326794896557...,
/// π/2 = 1.570796326794896619...).
const HALF_PI: Interval = Interval {
    lo: FRAC_PI_2,
    hi: 1.570_796_326_794_896_8,
};

impl Interval {
    /// π: the nearest f64 and the one above it.
    pub const PI: Interval = Interval {
        lo: std::f64::consts::PI,
        hi: 3.141_592_653_589_793_6,
    };

    /// Every real.
    pub const ENTIRE: Interval = Interval {
        lo: f64::NEG_INFINITY,
        hi: f64::INFINITY,
    };

    /// [lo, hi]; the whole line where a bound is NaN (an operation that has no meaning
    /// somewhere on its operands, such as infinity minus infinity).
    pub fn new(lo: f64, hi: f64) -> Interval {
        if lo.is_nan() || hi.is_nan() {
            Interval::ENTIRE
        } else {
            debug_assert!(lo <= hi, "[{lo}, {hi}]");
            Interval { lo, hi }
        }
    }

    /// The single point x (the whole line for NaN).
    pub fn point(x: f64) -> Interval {
        Interval::new(x, x)
    }

    /// The least interval holding a and b.
    pub fn hull(a: f64, b: f64) -> Interval {
        Interval::new(a.min(b), a.max(b))
    }

    /// The least interval holding both.
    pub fn union(self, o: Interval) -> Interval {
        Interval::new(self.lo.min(o.lo), self.hi.max(o.hi))
    }

    /// The lower bound.
    pub fn lo(self) -> f64 {
        self.lo
    }

    /// The upper bound.
    pub fn hi(self) -> f64 {
        self.hi
    }

    /// hi - lo, rounded up.
    pub fn width(self) -> f64 {
        up(self.hi - self.lo)
    }

    /// The largest |x| over the interval.
    pub fn mag(self) -> f64 {
        self.lo.abs().max(self.hi.abs())
    }

    /// Whether x lies in the interval.
    pub fn contains(self, x: f64) -> bool {
        self.lo <= x && x <= self.hi
    }

    /// The midpoint (a finite point of the interval, 0 for the whole line).
    pub fn mid(self) -> f64 {
        match (self.lo.is_finite(), self.hi.is_finite()) {
            (true, true) => {
                let m = self.lo + 0.5 * (self.hi - self.lo);
                if m.is_finite() {
                    m.clamp(self.lo, self.hi)
                } else {
                    0.5 * self.lo + 0.5 * self.hi
                }
            }
            (true, false) => self.lo.max(0.0),
            (false, true) => self.hi.min(0.0),
            (false, false) => 0.0,
        }
    }

    /// The common part, if any.
    pub fn intersect(self, o: Interval) -> Option<Interval> {
        let (lo, hi) = (self.lo.max(o.lo), self.hi.min(o.hi));
        (lo <= hi).then_some(Interval { lo, hi })
    }

    /// Whether the two share a point.
    pub fn meets(self, o: Interval) -> bool {
        self.lo <= o.hi && o.lo <= self.hi
    }

    /// Whether `o` lies in the interior of this interval (strictly inside both bounds).
    pub fn holds_inside(self, o: Interval) -> bool {
        self.lo < o.lo && o.hi < self.hi
    }

    /// Whether `o` lies in this interval (bounds included).
    pub fn holds(self, o: Interval) -> bool {
        self.lo <= o.lo && o.hi <= self.hi
    }

    /// Whether both bounds are finite.
    pub fn is_bounded(self) -> bool {
        self.lo.is_finite() && self.hi.is_finite()
    }

    /// The bounds of a sum or a difference moved one unit outward, but for an exact 0: a
    /// sum of two f64 that rounds to 0 is 0 (a nonzero one is at least the least
    /// subnormal, and sums that small are exact), so that 1 - 1 stays 0 and a square root
    /// of it stays defined.
    #[inline]
    fn summed(lo: f64, hi: f64) -> Interval {
        let exact = |x: f64, out: fn(f64) -> f64| if x == 0.0 { 0.0 } else { out(x) };
        Interval::new(exact(lo, down), exact(hi, up))
    }

    /// The bounds moved one unit outward.
    #[inline]
    fn widened(lo: f64, hi: f64) -> Interval {
        Interval::new(down(lo), up(hi))
    }

    /// x^2 (tighter than x * x where the interval holds 0).
    pub fn sqr(self) -> Interval {
        let (a, b) = (self.lo * self.lo, self.hi * self.hi);
        if self.lo <= 0.0 && 0.0 <= self.hi {
            Interval::new(0.0, up(a.max(b)))
        } else {
            Interval::widened(a.min(b), a.max(b))
        }
    }

    /// x^n for an integer n (x^0 = 1; a negative n is 1 / x^-n).
    pub fn powi(self, n: i32) -> Interval {
        if n < 0 {
            return Interval::point(1.0) / self.powi(n.saturating_neg());
        }
        // By squaring (as many steps as n has bits): x^n = x^(n mod 2) (x^2)^(n / 2), each
        // square from `sqr`; an even power is not below 0 (which the products' outward
        // rounding of an exact 0 would give).
        let (mut out, mut square, mut e) = (Interval::point(1.0), self, n.unsigned_abs());
        while e > 0 {
            if e & 1 == 1 {
                out = out * square;
            }
            e >>= 1;
            if e > 0 {
                square = square.sqr();
            }
        }
        if n % 2 == 0 {
            Interval::new(out.lo.max(0.0), out.hi)
        } else {
            out
        }
    }

    /// |x|.
    pub fn abs(self) -> Interval {
        if self.lo >= 0.0 {
            self
        } else if self.hi <= 0.0 {
            -self
        } else {
            Interval::new(0.0, (-self.lo).max(self.hi))
        }
    }

    /// The pointwise least of two.
    pub fn min(self, o: Interval) -> Interval {
        Interval::new(self.lo.min(o.lo), self.hi.min(o.hi))
    }

    /// The pointwise greatest of two.
    pub fn max(self, o: Interval) -> Interval {
        Interval::new(self.lo.max(o.lo), self.hi.max(o.hi))
    }

    /// The square root; the whole line where the interval reaches below 0.
    pub fn sqrt(self) -> Interval {
        if self.lo < 0.0 {
            return Interval::ENTIRE;
        }
        Interval::new(down(self.lo.sqrt()).max(0.0), up(self.hi.sqrt()))
    }

    /// e^x.
    pub fn exp(self) -> Interval {
        let (lo, hi) = ends(self, exp_point);
        Interval::new(lo.lo.max(0.0), hi.hi)
    }

    /// The natural logarithm; the whole line where the interval reaches 0 or below.
    pub fn ln(self) -> Interval {
        if self.lo <= 0.0 {
            return Interval::ENTIRE;
        }
        let (lo, hi) = ends(self, ln_point);
        Interval::new(lo.lo, hi.hi)
    }

    /// x^k for a real k, as e^(k ln x): x > 0, or x >= 0 for k > 0; the whole line
    /// elsewhere.
    pub fn powf(self, k: f64) -> Interval {
        if k == 0.0 {
            return Interval::point(1.0);
        }
        if self.lo < 0.0 || (self.lo == 0.0 && k < 0.0) {
            return Interval::ENTIRE;
        }
        if self.lo == 0.0 {
            // k > 0: increasing from 0.
            if self.hi == 0.0 {
                return Interval::point(0.0);
            }
            let hi = (Interval::point(self.hi).ln() * Interval::point(k)).exp();
            return Interval::new(0.0, hi.hi);
        }
        (self.ln() * Interval::point(k)).exp()
    }

    /// x^y as e^(y ln x), x > 0; the whole line elsewhere.
    pub fn pow(self, y: Interval) -> Interval {
        if self.lo <= 0.0 {
            return Interval::ENTIRE;
        }
        (self.ln() * y).exp()
    }

    /// sin.
    pub fn sin(self) -> Interval {
        sin_cos(self).0
    }

    /// cos.
    pub fn cos(self) -> Interval {
        sin_cos(self).1
    }

    /// sin and cos, from one reduction.
    pub fn sin_cos(self) -> (Interval, Interval) {
        sin_cos(self)
    }

    /// tan, as sin / cos; the whole line where the interval may hold a pole.
    pub fn tan(self) -> Interval {
        self.sin() / self.cos()
    }

    /// atan.
    pub fn atan(self) -> Interval {
        let (lo, hi) = ends(self, atan_point);
        Interval::new(lo.lo, hi.hi)
    }

    /// asin; the whole line where the interval leaves [-1, 1].
    pub fn asin(self) -> Interval {
        if self.lo < -1.0 || self.hi > 1.0 {
            return Interval::ENTIRE;
        }
        let (lo, hi) = ends(self, asin_point);
        Interval::new(lo.lo, hi.hi)
    }

    /// acos, as π/2 - asin; the whole line where the interval leaves [-1, 1].
    pub fn acos(self) -> Interval {
        HALF_PI - self.asin()
    }

    /// atan2(y = self, x), the angle of (x, y) in [-π, π]: all of [-π, π] where the box
    /// of (x, y) holds the origin or reaches the cut along the negative x axis.
    pub fn atan2(self, x: Interval) -> Interval {
        let pi = HALF_PI + HALF_PI;
        let all = Interval::new(-pi.hi, pi.hi);
        let (y, x) = (self, x);
        if x.lo > 0.0 {
            // Right half plane: atan(y / x), monotone in each of y and x there.
            (y / x).atan()
        } else if y.lo > 0.0 {
            // Upper half plane: π/2 - atan(x / y).
            HALF_PI - (x / y).atan()
        } else if y.hi < 0.0 {
            // Lower half plane: -π/2 - atan(x / y).
            -HALF_PI - (x / y).atan()
        } else {
            all
        }
    }

    /// sinh, as (e^x - e^-x) / 2 at each end (sinh is increasing).
    pub fn sinh(self) -> Interval {
        let at = |x: f64| {
            let x = Interval::point(x);
            (x.exp() - (-x).exp()) * Interval::point(0.5)
        };
        let (lo, hi) = ends(self, at);
        Interval::new(lo.lo, hi.hi)
    }

    /// cosh, as (e^x + e^-x) / 2 at the end farther from 0, at least 1.
    pub fn cosh(self) -> Interval {
        let at = |x: f64| {
            let x = Interval::point(x);
            (x.exp() + (-x).exp()) * Interval::point(0.5)
        };
        let a = self.abs();
        let (lo, hi) = ends(a, at);
        Interval::new(lo.lo.max(1.0), hi.hi)
    }

    /// tanh, as 1 - 2 / (e^(2x) + 1) at each end (tanh is increasing), within [-1, 1].
    pub fn tanh(self) -> Interval {
        let at = |x: f64| {
            // For x >= 0, e^(2x) >= 1 keeps the division away from 0; tanh(-x) = -tanh(x)
            // for the rest.
            let t = |x: f64| {
                let e = (Interval::point(2.0) * Interval::point(x)).exp();
                Interval::point(1.0) - Interval::point(2.0) / (e + Interval::point(1.0))
            };
            if x < 0.0 { -t(-x) } else { t(x) }
        };
        let (lo, hi) = ends(self, at);
        Interval::new(lo.lo.max(-1.0), hi.hi.min(1.0))
    }
}

/// Written as `[lo, hi]`.
impl serde::Serialize for Interval {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        [self.lo, self.hi].serialize(serializer)
    }
}

impl From<f64> for Interval {
    fn from(x: f64) -> Interval {
        Interval::point(x)
    }
}

impl Add for Interval {
    type Output = Interval;
    #[inline]
    fn add(self, o: Interval) -> Interval {
        Interval::summed(self.lo + o.lo, self.hi + o.hi)
    }
}

impl Sub for Interval {
    type Output = Interval;
    #[inline]
    fn sub(self, o: Interval) -> Interval {
        Interval::summed(self.lo - o.hi, self.hi - o.lo)
    }
}

impl Neg for Interval {
    type Output = Interval;
    #[inline]
    fn neg(self) -> Interval {
        Interval::new(-self.hi, -self.lo)
    }
}

impl Mul for Interval {
    type Output = Interval;
    #[inline]
    fn mul(self, o: Interval) -> Interval {
        // One factor not below 0 (most products in the series): two products decide.
        if o.lo >= 0.0 {
            let lo = self.lo * if self.lo >= 0.0 { o.lo } else { o.hi };
            let hi = self.hi * if self.hi >= 0.0 { o.hi } else { o.lo };
            // 0 times infinity is NaN, and the whole line.
            return Interval::widened(lo, hi);
        }
        if self.lo >= 0.0 {
            let lo = o.lo * if o.lo >= 0.0 { self.lo } else { self.hi };
            let hi = o.hi * if o.hi >= 0.0 { self.hi } else { self.lo };
            return Interval::widened(lo, hi);
        }
        let p = [
            self.lo * o.lo,
            self.lo * o.hi,
            self.hi * o.lo,
            self.hi * o.hi,
        ];
        if p.iter().any(|x| x.is_nan()) {
            // 0 times infinity: nothing is claimed.
            return Interval::ENTIRE;
        }
        let lo = p.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = p.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        Interval::widened(lo, hi)
    }
}

impl Div for Interval {
    type Output = Interval;
    fn div(self, o: Interval) -> Interval {
        if o.lo <= 0.0 && 0.0 <= o.hi {
            return Interval::ENTIRE;
        }
        let q = [
            self.lo / o.lo,
            self.lo / o.hi,
            self.hi / o.lo,
            self.hi / o.hi,
        ];
        if q.iter().any(|x| x.is_nan()) {
            return Interval::ENTIRE;
        }
        let lo = q.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = q.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        Interval::widened(lo, hi)
    }
}

/// A function's enclosures at the two ends of `x`, computed once for a point.
fn ends(x: Interval, at: impl Fn(f64) -> Interval) -> (Interval, Interval) {
    let lo = at(x.lo);
    (lo, if x.hi == x.lo { lo } else { at(x.hi) })
}

/// An upper bound of |r|^n / n! for the series' remainders, rounded up at each step.
fn remainder(r: f64, n: u32) -> f64 {
    up(pow_up(r, n) * SERIES.inverse_factorial[n as usize])
}

/// An upper bound of r^n for r >= 0, rounded up at each step.
fn pow_up(r: f64, n: u32) -> f64 {
    // By squaring, each product of numbers >= 0 rounded up: a short chain of steps.
    let (mut out, mut square, mut e) = (1.0f64, r, n);
    while e > 0 {
        if e & 1 == 1 {
            out = up(out * square);
        }
        e >>= 1;
        if e > 0 {
            square = up(square * square);
        }
    }
    out
}

/// Σ c_k x^k over the `coefficients` c_k, by Horner's rule in interval arithmetic (an
/// enclosure of the polynomial over all of x).
fn horner(x: Interval, coefficients: &[Interval]) -> Interval {
    coefficients
        .iter()
        .rev()
        .fold(Interval::point(0.0), |out, &c| out * x + c)
}

/// An enclosure of n! (exact as an f64 up to 22!, and an interval around it beyond).
fn factorial(n: usize) -> Interval {
    (1..=n).fold(Interval::point(1.0), |p, k| p * Interval::point(k as f64))
}

/// Enclosures of the series' coefficients, made once: 1 / k! for e^x; (-1)^n / (2n+1)!
/// and (-1)^n / (2n)! for sin and cos (in powers of x^2); 1 / (2n+1) for atanh and
/// (-1)^n / (2n+1) for atan (in powers of x^2).
struct Series {
    exp: [Interval; EXP_TERMS as usize],
    sin: [Interval; TRIG_TERMS as usize],
    cos: [Interval; TRIG_TERMS as usize],
    atanh: [Interval; ODD_TERMS as usize],
    atan: [Interval; ODD_TERMS as usize],
    /// Upper bounds of 1 / n!, for the remainders.
    inverse_factorial: [f64; 2 * TRIG_TERMS as usize + 2],
}

/// Terms of the series: each leaves a remainder below 1e-19 of 1 at the largest argument
/// its reduction leaves (|r| <= ln 2 / 2 for e^r, π/4 for sin and cos, 0.2 for atan and
/// atanh), far below the unit in the last place that the enclosures' rounding adds.
const EXP_TERMS: u32 = 17;
const TRIG_TERMS: u32 = 10;
const ODD_TERMS: u32 = 13;

static SERIES: std::sync::LazyLock<Series> = std::sync::LazyLock::new(|| {
    let one = Interval::point(1.0);
    let sign = |n: usize, c: Interval| if n % 2 == 1 { -c } else { c };
    let odd = |n: usize| Interval::point((2 * n + 1) as f64);
    Series {
        exp: std::array::from_fn(|k| one / factorial(k)),
        sin: std::array::from_fn(|n| sign(n, one / factorial(2 * n + 1))),
        cos: std::array::from_fn(|n| sign(n, one / factorial(2 * n))),
        atanh: std::array::from_fn(|n| one / odd(n)),
        atan: std::array::from_fn(|n| sign(n, one / odd(n))),
        inverse_factorial: std::array::from_fn(|n| (one / factorial(n)).hi),
    }
});

/// An enclosure of e^x at the point x.
fn exp_point(x: f64) -> Interval {
    if x.is_nan() {
        return Interval::ENTIRE;
    }
    if x > 709.0 {
        // Above e^709 (8.2e307): the rest of the line.
        return Interval::new(exp_point(709.0).lo, f64::INFINITY);
    }
    if x < -745.0 {
        // Below the least positive f64.
        return Interval::new(0.0, f64::from_bits(1));
    }
    // x = k ln 2 + r, |r| <= ln 2 / 2 (a little more from the rounding of k).
    let k = (x / LN_2).round();
    let r = Interval::point(x) - Interval::point(k) * LN2;
    // e^r = Σ r^n / n! for n < EXP_TERMS, and the rest below |r|^N / N! e^|r| (< 2 |r|^N /
    // N!, N = EXP_TERMS).
    let series = horner(r, &SERIES.exp);
    let rest = 2.0 * remainder(r.mag(), EXP_TERMS);
    let e = series + Interval::new(-rest, rest);
    // 2^k in two steps, each exact, so that 2^k itself need not be a normal number.
    let half = (k / 2.0).trunc();
    e * Interval::point(2f64.powi(half as i32)) * Interval::point(2f64.powi((k - half) as i32))
}

/// An enclosure of ln x at the point x > 0.
fn ln_point(x: f64) -> Interval {
    if x.is_infinite() {
        return Interval::new(ln_point(f64::MAX).lo, f64::INFINITY);
    }
    // x = m 2^e with m in [1/√2, √2): exact scalings by powers of two.
    let (mut m, mut e) = (x, 0i32);
    while m < std::f64::consts::FRAC_1_SQRT_2 {
        m *= 2.0;
        e -= 1;
    }
    while m >= std::f64::consts::SQRT_2 {
        m *= 0.5;
        e += 1;
    }
    // ln m = 2 atanh s, s = (m - 1) / (m + 1), |s| < 0.172: 2 Σ s^(2n+1) / (2n+1) for
    // n < N = ODD_TERMS, the rest below 2 |s|^(2N+1) / ((2N+1) (1 - s^2)) < 3 |s|^(2N+1) /
    // (2N+1).
    let s =
        (Interval::point(m) - Interval::point(1.0)) / (Interval::point(m) + Interval::point(1.0));
    let series = s * horner(s.sqr(), &SERIES.atanh);
    let odd = 2 * ODD_TERMS + 1;
    let rest = up(up(3.0 * pow_up(s.mag(), odd)) / f64::from(odd));
    Interval::point(f64::from(e)) * LN2
        + Interval::point(2.0) * (series + Interval::new(-rest, rest))
}

/// sin and cos over an interval: for each, the hull of the values at its ends, with 1
/// where it may hold a maximum and -1 where it may hold a minimum. One reduction serves
/// both.
fn sin_cos(x: Interval) -> (Interval, Interval) {
    let full = Interval::new(-1.0, 1.0);
    // Beyond 1e15 the reduction by π/2 tells nothing (and the multiples would not fit).
    if !x.is_bounded() || x.width() >= 6.0 || x.mag() > 1e15 {
        return (full, full);
    }
    let (a, b) = ends2(x, trig_point);
    let mut out = [0, 1].map(|i| (a[i].lo.min(b[i].lo), a[i].hi.max(b[i].hi)));
    // The multiples of π/2 the interval may hold (an enclosure of x / (π/2), so that an
    // extremum inside x is found, and one just outside may be too: a looser bound).
    let q = x / HALF_PI;
    let (first, last) = (q.lo.ceil() as i64, q.hi.floor() as i64);
    for n in first..=last {
        // sin: 1 at 1 mod 4, -1 at 3 mod 4; cos: 1 at 0 mod 4, -1 at 2 mod 4.
        for (i, (lo, hi)) in out.iter_mut().enumerate() {
            match (n + i as i64).rem_euclid(4) {
                1 => *hi = 1.0,
                3 => *lo = -1.0,
                _ => {}
            }
        }
    }
    let [s, c] = out.map(|(lo, hi)| Interval::new(lo.max(-1.0), hi.min(1.0)));
    (s, c)
}

/// [`ends`] of a function with two values.
fn ends2(x: Interval, at: impl Fn(f64) -> [Interval; 2]) -> ([Interval; 2], [Interval; 2]) {
    let lo = at(x.lo);
    (lo, if x.hi == x.lo { lo } else { at(x.hi) })
}

/// Enclosures of sin and cos at the point t.
fn trig_point(t: f64) -> [Interval; 2] {
    if !t.is_finite() || t.abs() > 1e15 {
        return [Interval::new(-1.0, 1.0); 2];
    }
    // t = k π/2 + r, |r| <= π/4 (a little more from the rounding of k).
    let k = (t / FRAC_PI_2).round();
    let r = Interval::point(t) - Interval::point(k) * HALF_PI;
    let m = r.mag();
    // sin r = r Σ (-1)^n r^2n / (2n+1)!, cos r = Σ (-1)^n r^2n / (2n)!, for n < N =
    // TRIG_TERMS; the rest below |r|^(2N+1) / (2N+1)! and |r|^2N / (2N)! (each derivative
    // at most 1).
    let r2 = r.sqr();
    let sin = r * horner(r2, &SERIES.sin);
    let cos = horner(r2, &SERIES.cos);
    let (s_rest, c_rest) = (
        remainder(m, 2 * TRIG_TERMS + 1),
        remainder(m, 2 * TRIG_TERMS),
    );
    let sin = sin + Interval::new(-s_rest, s_rest);
    let cos = cos + Interval::new(-c_rest, c_rest);
    // sin and cos of r + k π/2.
    match (k as i64).rem_euclid(4) {
        0 => [sin, cos],
        1 => [cos, -sin],
        2 => [-sin, -cos],
        _ => [-cos, sin],
    }
}

/// An enclosure of atan at the point t.
fn atan_point(t: f64) -> Interval {
    if t.is_nan() {
        return Interval::ENTIRE;
    }
    if t.is_infinite() {
        return if t > 0.0 { HALF_PI } else { -HALF_PI };
    }
    if t.abs() > 1.0 {
        // atan t = ±π/2 - atan(1/t).
        let small = atan_small(Interval::point(1.0) / Interval::point(t));
        return if t > 0.0 {
            HALF_PI - small
        } else {
            -HALF_PI - small
        };
    }
    atan_small(Interval::point(t))
}

/// atan over an interval within [-1, 1]: halved twice (atan t = 2 atan(t / (1 + √(1 +
/// t^2)))) to |t| <= tan(π/16) < 0.2, then Σ (-1)^n t^(2n+1) / (2n+1) for n < N =
/// ODD_TERMS, the rest below |t|^(2N+1) / (2N+1).
fn atan_small(t: Interval) -> Interval {
    let one = Interval::point(1.0);
    let half = |t: Interval| t / (one + (one + t.sqr()).sqrt());
    let s = half(half(t));
    let series = s * horner(s.sqr(), &SERIES.atan);
    let odd = 2 * ODD_TERMS + 1;
    let rest = up(pow_up(s.mag(), odd) / f64::from(odd));
    Interval::point(4.0) * (series + Interval::new(-rest, rest))
}

/// An enclosure of asin at the point t in [-1, 1]: atan(t / √(1 - t^2)), ±π/2 at ±1.
fn asin_point(t: f64) -> Interval {
    if t == 1.0 {
        return HALF_PI;
    }
    if t == -1.0 {
        return -HALF_PI;
    }
    let x = Interval::point(t);
    let one = Interval::point(1.0);
    let root = ((one - x) * (one + x)).sqrt();
    // atan of the quotient, an interval: atan is increasing, so its ends bound it.
    let q = x / root;
    Interval::new(atan_point(q.lo).lo, atan_point(q.hi).hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points spread over [lo, hi], its ends among them.
    fn spread(lo: f64, hi: f64, n: usize) -> Vec<f64> {
        (0..=n)
            .map(|k| (lo + (hi - lo) * k as f64 / n as f64).clamp(lo, hi))
            .chain([lo, hi])
            .collect()
    }

    /// Checks that `f` over intervals encloses `g` (the platform's function, accurate to a
    /// unit or two) at every point of many intervals within [lo, hi], and that a point's
    /// enclosure is narrow (so that a test that passes is not passing on the whole line).
    fn encloses(
        name: &str,
        f: impl Fn(Interval) -> Interval,
        g: impl Fn(f64) -> f64,
        lo: f64,
        hi: f64,
    ) {
        let ends = spread(lo, hi, 97);
        for (i, &a) in ends.iter().enumerate() {
            for &b in &ends[i..] {
                let x = Interval::hull(a, b);
                let y = f(x);
                for t in spread(x.lo, x.hi, 13) {
                    let v = g(t);
                    // The platform's value may be a unit off the true one: allow one unit
                    // beyond the enclosure, which is itself rigorous.
                    let slack = Interval::new(down(y.lo), up(y.hi));
                    assert!(
                        slack.contains(v),
                        "{name}({x:?}) = {y:?} misses {name}({t}) = {v}"
                    );
                }
            }
            let y = f(Interval::point(a));
            let v = g(a);
            assert!(
                y.width() <= 1e-13 * v.abs().max(1.0),
                "{name}({a}) = {y:?}, too wide"
            );
        }
    }

    #[test]
    fn the_elementary_functions_enclose_their_values() {
        encloses("exp", Interval::exp, f64::exp, -30.0, 30.0);
        encloses("ln", Interval::ln, f64::ln, 1e-6, 1e6);
        encloses("sin", Interval::sin, f64::sin, -20.0, 20.0);
        encloses("cos", Interval::cos, f64::cos, -20.0, 20.0);
        encloses("atan", Interval::atan, f64::atan, -50.0, 50.0);
        encloses("asin", Interval::asin, f64::asin, -1.0, 1.0);
        encloses("acos", Interval::acos, f64::acos, -1.0, 1.0);
        encloses("sinh", Interval::sinh, f64::sinh, -5.0, 5.0);
        encloses("cosh", Interval::cosh, f64::cosh, -5.0, 5.0);
        encloses("tanh", Interval::tanh, f64::tanh, -5.0, 5.0);
        encloses("sqrt", Interval::sqrt, f64::sqrt, 0.0, 9.0);
        encloses("sqr", Interval::sqr, |x| x * x, -3.0, 2.0);
        encloses("cube", |x| x.powi(3), |x| x.powi(3), -3.0, 2.0);
        encloses("x^7", |x| x.powi(7), |x| x.powi(7), -3.0, 2.0);
        encloses("x^8", |x| x.powi(8), |x| x.powi(8), -3.0, 2.0);
        encloses("x^-2", |x| x.powi(-2), |x| x.powi(-2), 0.5, 3.0);
        encloses("x^2.5", |x| x.powf(2.5), |x| x.powf(2.5), 0.0, 3.0);
        encloses("abs", Interval::abs, f64::abs, -3.0, 2.0);
    }

    #[test]
    fn the_constants_are_the_f64_below_and_the_one_above() {
        // ln 2 = 0.693147180559945309417..., π/2 = 1.570796326794896619231...: each nearest
        // f64 is below the true value.
        assert_eq!(LN2.lo, LN_2);
        assert_eq!(LN2.hi, LN_2.next_up());
        assert_eq!(HALF_PI.lo, FRAC_PI_2);
        assert_eq!(HALF_PI.hi, FRAC_PI_2.next_up());
    }

    #[test]
    fn exact_values_and_extrema_are_inside() {
        let pi = HALF_PI + HALF_PI;
        assert!(pi.contains(std::f64::consts::PI) && pi.width() < 2e-15);
        // The true π lies strictly between the f64 and the next one up.
        assert!(pi.lo < std::f64::consts::PI.next_up() && pi.hi >= std::f64::consts::PI);
        assert!(Interval::point(0.0).sin().contains(0.0));
        assert!(Interval::point(0.0).cos().contains(1.0));
        assert!(Interval::point(0.0).exp().contains(1.0));
        assert!(Interval::point(1.0).ln().contains(0.0));
        assert!(
            Interval::point(1.0)
                .atan()
                .contains(std::f64::consts::FRAC_PI_4)
        );
        // ln 2 of the series against the constant: both enclose the true value.
        let l = Interval::point(2.0).ln();
        assert!(l.lo <= LN2.hi && LN2.lo <= l.hi);
        // e^(ln 10) holds 10.
        assert!(Interval::point(10.0).ln().exp().contains(10.0));
        // An interval around π/2 reaches sin's maximum even though neither end does.
        let s = Interval::new(1.5, 1.7).sin();
        assert_eq!(s.hi, 1.0);
        assert!(s.lo <= 1.7f64.sin() && s.lo > 0.99);
        // Around π, cos's minimum; around 0, its maximum.
        assert_eq!(Interval::new(3.0, 3.3).cos().lo, -1.0);
        assert_eq!(Interval::new(-0.1, 0.2).cos().hi, 1.0);
        // Wide intervals: all of [-1, 1].
        assert_eq!(Interval::new(0.0, 7.0).sin(), Interval::new(-1.0, 1.0));
    }

    #[test]
    fn large_powers_take_as_many_steps_as_their_bits() {
        // (1 + 1e-9)^1e9 = e^(1e9 ln(1 + 1e-9)) = 2.7182818270...: a billion multiplications
        // one by one would take seconds. Each squaring doubles the relative width.
        let x = 1.0 + 1e-9;
        let p = Interval::point(x).powi(1_000_000_000);
        let e = (1e9 * x.ln()).exp();
        assert!(p.contains(e) && p.width() < 1e-5, "{p:?} against {e}");
        assert!(Interval::point(1.0).powi(i32::MAX).contains(1.0));
        assert_eq!(Interval::new(-1.0, 0.5).powi(i32::MIN), Interval::ENTIRE);
        // Even powers of an interval around 0 never go below 0.
        assert_eq!(Interval::new(-2.0, 1.0).powi(6).lo(), 0.0);
    }

    #[test]
    fn what_is_undefined_somewhere_claims_nothing() {
        let around_zero = Interval::new(-1.0, 1.0);
        assert_eq!(Interval::point(1.0) / around_zero, Interval::ENTIRE);
        assert_eq!(around_zero.ln(), Interval::ENTIRE);
        assert_eq!(around_zero.sqrt(), Interval::ENTIRE);
        assert_eq!(Interval::new(0.5, 1.5).asin(), Interval::ENTIRE);
        assert_eq!(Interval::new(1.5, 1.6).tan(), Interval::ENTIRE);
        assert_eq!(Interval::point(f64::NAN), Interval::ENTIRE);
        assert_eq!(Interval::point(0.0) * Interval::ENTIRE, Interval::ENTIRE);
        // Far out: still an enclosure, never NaN.
        let big = Interval::point(800.0).exp();
        assert!(big.hi.is_infinite() && big.lo > 1e307);
        assert!(Interval::point(-800.0).exp().contains(0.0));
        assert_eq!(Interval::point(1e300).sin(), Interval::new(-1.0, 1.0));
        assert_eq!(Interval::new(1e300, 1e300).cos(), Interval::new(-1.0, 1.0));
    }

    #[test]
    fn atan2_encloses_the_angle_off_its_cut() {
        for (y, x) in [
            (1.0, 2.0),
            (1.0, -2.0),
            (-1.0, -2.0),
            (-3.0, 0.5),
            (2.0, 0.0),
        ] {
            let box_y = Interval::new(y - 0.1, y + 0.1);
            let box_x = Interval::new(x - 0.1, x + 0.1);
            let a = box_y.atan2(box_x);
            for dy in [-0.1, 0.0, 0.1] {
                for dx in [-0.1, 0.0, 0.1] {
                    let v = (y + dy).atan2(x + dx);
                    assert!(
                        Interval::new(down(a.lo), up(a.hi)).contains(v),
                        "atan2 over ({y}, {x}) = {a:?} misses {v}"
                    );
                }
            }
        }
        // Across the cut: all of [-π, π].
        let a = Interval::new(-0.1, 0.1).atan2(Interval::new(-2.0, -1.0));
        assert!(a.contains(-std::f64::consts::PI) && a.contains(std::f64::consts::PI));
    }

    #[test]
    fn sums_keep_an_exact_zero() {
        let zero = Interval::point(-1.0) + Interval::point(1.0);
        assert_eq!(zero, Interval::point(0.0));
        let root = zero.sqrt();
        assert!(
            root.lo() == 0.0 && root.hi() <= f64::from_bits(1),
            "{root:?}"
        );
        assert_eq!(
            Interval::point(0.5) - Interval::point(0.5),
            Interval::point(0.0)
        );
        // An inexact sum is still widened.
        let third = Interval::point(0.1) + Interval::point(0.2);
        assert!(third.lo() < 0.1 + 0.2 && 0.1 + 0.2 < third.hi());
    }
}
