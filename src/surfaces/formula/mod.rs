//! Surfaces written as formulas in the scene: `{"type": "formula", "x": "cos(u)", ...}`.
//!
//! Takes: four expressions in u, v, the constants `pi` and `e` and named parameters; the
//! ranges of u and v; the rules of the four sides. Gives: a [`Formula`] surface whose
//! points and exact first and second derivatives come from the expressions, compiled once
//! into postfix programs that run over [`Jet`]s (and over plain f64 for points alone), with
//! its [`Domain`] and its [`Topology`] derived from the side rules, never from a mesh.
//!
//! Guarantees: [`Formula::new`] accepts only formulas that parse, name known names and call
//! functions with their number of arguments, within [`FORMULA_LENGTH`], [`FORMULA_DEPTH`]
//! and [`FORMULA_EXPONENT`]; every error names the field and points at the character with
//! a caret. [`Formula`]'s check (the scene's) evaluates the surface on a grid of the domain
//! and rejects non-finite points anywhere, non-finite derivatives inside the domain (on its
//! sides they are tolerated where the sampler's inward tangents are finite), bends beyond
//! [`FORMULA_BEND`], and glued sides or poles whose points do not meet.
//!
//! The parser is hand-written recursive descent: meval and fasteval evaluate f64 only,
//! evalexpr's numeric types must also serve its dynamic values (strings, tuples, booleans,
//! Display and FromStr), and none of them gives the character positions a caret needs.
//!
//! The files beside this one, in the order a formula goes through them: [`lexer`] (text to
//! tokens), [`parser`] (tokens to postfix instructions, with the compile-time checks),
//! [`compiler`] (the instruction set, one formula's program and the four programs merged
//! into one), [`evaluator`] (running them over f64 and [`Jet`]s); beside them [`messages`]
//! (the caret and the words for a value that is not finite), [`sides`] (the side rules:
//! domain, topology) and [`check`] (the scene's check on a grid). This file holds the
//! public types and [`Formula::new`].
//!
//! [`FORMULA_LENGTH`]: crate::limits::FORMULA_LENGTH
//! [`FORMULA_DEPTH`]: crate::limits::FORMULA_DEPTH
//! [`FORMULA_EXPONENT`]: crate::limits::FORMULA_EXPONENT
//! [`FORMULA_BEND`]: crate::limits::FORMULA_BEND

mod check;
mod compiler;
mod evaluator;
mod lexer;
mod messages;
mod parser;
mod sides;

use super::{Domain, Eval4, Interval, Jet, Parametric, Topology};
use crate::limits::{FINITE, FieldError, shorten};
use compiler::{Op, Program, Shared, function};
use glam::DVec4;
use serde::{Deserialize, Serialize};
use sides::Kind;
use std::collections::BTreeMap;

/// A surface given by four formulas, as written in a scene:
/// `{"type": "formula", "x": "cos(u)", "y": "sin(u)", "z": "cos(v)", "w": "sin(v)",
/// "u": [0, 6.283185307179586], "v": [0, 6.283185307179586],
/// "sides": {"u": "periodic", "v": "periodic"}}`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FormulaSource {
    /// The first coordinate, a formula in u, v, `pi`, `e` and the parameters.
    pub x: String,
    /// The second coordinate.
    pub y: String,
    /// The third coordinate.
    pub z: String,
    /// The fourth coordinate.
    pub w: String,
    /// The range of u, `[min, max]`, finite with min < max: numbers, or formulas of numbers,
    /// `pi`, `e` and the parameters (`[0, "2*pi"]`).
    pub u: [Bound; 2],
    /// The range of v.
    pub v: [Bound; 2],
    /// The rules of the sides of the parameter rectangle; all open when omitted.
    #[serde(default, skip_serializing_if = "FormulaSides::all_open")]
    pub sides: FormulaSides,
    /// Named constants the formulas may use.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub parameters: BTreeMap<String, f64>,
}

/// An end of a parameter range: a number, or a formula without u and v (`"2*pi"`, `"pi/a"`),
/// so that a period is exactly the f64 nearest 2π and not a rounded one.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Bound {
    /// A number.
    Number(f64),
    /// A formula of numbers, `pi`, `e` and the parameters.
    Formula(String),
}

impl From<f64> for Bound {
    fn from(x: f64) -> Self {
        Bound::Number(x)
    }
}

impl From<&str> for Bound {
    fn from(text: &str) -> Self {
        Bound::Formula(text.to_string())
    }
}

impl Bound {
    /// The value, or what is wrong with the formula.
    fn value(&self, parameters: &BTreeMap<String, f64>) -> Result<f64, String> {
        match self {
            Bound::Number(x) => Ok(*x),
            Bound::Formula(text) => {
                let program = Program::compile(text, parameters)?;
                if program.ops.iter().any(|op| matches!(op, Op::U | Op::V)) {
                    return Err(format!(
                        "`{}`: a range's end may use numbers, pi, e and the parameters, not u or v",
                        shorten(text)
                    ));
                }
                Ok(program.run(0.0, 0.0))
            }
        }
    }
}

/// The rules of a formula surface's sides: `{"u": "periodic", "v_min": "pole"}`. `u` sets
/// both u sides at once and excludes `u_min` and `u_max` (the same for v); a side that no
/// key names is open.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FormulaSides {
    /// Both u sides (u = u_min and u = u_max).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub u: Option<FormulaSeam>,
    /// Both v sides.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub v: Option<FormulaSeam>,
    /// The side u = u_min alone.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub u_min: Option<FormulaEdge>,
    /// The side u = u_max alone.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub u_max: Option<FormulaEdge>,
    /// The side v = v_min alone.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub v_min: Option<FormulaEdge>,
    /// The side v = v_max alone.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub v_max: Option<FormulaEdge>,
}

impl FormulaSides {
    /// Whether no side is glued or collapsed.
    pub fn all_open(&self) -> bool {
        self.kinds().iter().all(|k| *k == Kind::Open)
    }
}

/// What joins the two sides of one parameter (`"u": ...`, `"v": ...`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FormulaSeam {
    /// Both sides are open boundaries.
    Open,
    /// The two sides are glued straight: the parameter is periodic.
    Periodic,
    /// The two sides are glued with the other parameter reversed (the Klein bottle's u).
    Flip,
}

/// What happens at one side alone (`"u_min": ...`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FormulaEdge {
    /// An open boundary.
    Open,
    /// The whole side is one point of the surface.
    Pole,
    /// The side is glued to itself shifted by half its length (the projective plane's
    /// equator, antipodal points).
    HalfTurn,
}

/// A surface given by four formulas in (u, v), compiled. Made by [`Formula::new`] (or read
/// from a scene), which checks the formulas; serializes back to its [`FormulaSource`].
#[derive(Clone, Debug)]
pub struct Formula {
    // Boxed: a `Surface` is as large as its largest variant.
    source: Box<FormulaSource>,
    /// The ranges of u and v, evaluated.
    ranges: [[f64; 2]; 2],
    /// The four programs as one, for points and jets.
    shared: Box<Shared>,
    programs: Box<[Program; 4]>,
}

impl PartialEq for Formula {
    fn eq(&self, other: &Self) -> bool {
        self.source == other.source
    }
}

impl Serialize for Formula {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.source.serialize(s)
    }
}

impl<'de> Deserialize<'de> for Formula {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let source = FormulaSource::deserialize(d)?;
        Formula::new(source).map_err(serde::de::Error::custom)
    }
}

/// The names of the four coordinates, which are also their fields.
const COMPONENTS: [&str; 4] = ["x", "y", "z", "w"];

impl Formula {
    /// Checks the ranges, parameters and side keys and compiles the four formulas; the
    /// error names the field (`x`, `u`, `parameters.a`, `sides.u_min`) and, for a formula
    /// that does not parse, shows where with a caret.
    pub fn new(source: FormulaSource) -> Result<Formula, FieldError> {
        let mut ranges = [[0.0; 2]; 2];
        for (k, (field, bounds)) in [("u", &source.u), ("v", &source.v)].into_iter().enumerate() {
            for (end, b) in bounds.iter().enumerate() {
                ranges[k][end] = b
                    .value(&source.parameters)
                    .map_err(|m| FieldError::new(format!("{field}[{end}]"), m))?;
            }
            let r = ranges[k];
            if !(r[0].is_finite() && r[1].is_finite() && r[0] < r[1] && (r[1] - r[0]).is_finite()) {
                return Err(FieldError::new(
                    field,
                    format!(
                        "must be a range [min, max] of finite numbers with min < max, got [{}, {}]",
                        r[0], r[1]
                    ),
                ));
            }
        }
        for (name, value) in &source.parameters {
            let field = format!("parameters.{}", shorten(name));
            check_parameter_name(name).map_err(|m| FieldError::new(&field, m))?;
            FINITE.check(&field, *value)?;
        }
        let s = &source.sides;
        for (pair, lo, hi, name) in [
            (s.u.is_some(), s.u_min.is_some(), s.u_max.is_some(), "u"),
            (s.v.is_some(), s.v_min.is_some(), s.v_max.is_some(), "v"),
        ] {
            if pair && (lo || hi) {
                let key = if lo { "min" } else { "max" };
                return Err(FieldError::new(
                    format!("sides.{name}_{key}"),
                    format!(
                        "give either `{name}` (both {name} sides) or `{name}_min`/`{name}_max`, not both"
                    ),
                ));
            }
        }
        let texts = [&source.x, &source.y, &source.z, &source.w];
        let mut programs = Vec::with_capacity(4);
        for (field, text) in COMPONENTS.iter().zip(texts) {
            programs.push(
                Program::compile(text, &source.parameters)
                    .map_err(|m| FieldError::new(*field, m))?,
            );
        }
        let programs: [Program; 4] = programs
            .try_into()
            .map_err(|_| FieldError::new("x", "four formulas expected"))?;
        Ok(Formula {
            source: Box::new(source),
            ranges,
            shared: Box::new(Shared::new(&programs)),
            programs: Box::new(programs),
        })
    }

    /// What the user wrote: the formulas, ranges, sides and parameters.
    pub fn source(&self) -> &FormulaSource {
        &self.source
    }

    /// An example not in the catalogue, for `halo4d list`: a torus in R^4 whose tube turns
    /// `n` times through the zw plane while it goes once around the xy circle (embedded:
    /// the xy angle gives u, and the tube's angle is read off the rest).
    pub fn example() -> Formula {
        let source = FormulaSource {
            x: "(R + r*cos(v))*cos(u)".into(),
            y: "(R + r*cos(v))*sin(u)".into(),
            z: "r*sin(v)*cos(n*u)".into(),
            w: "r*sin(v)*sin(n*u)".into(),
            u: [0.0.into(), "2*pi".into()],
            v: [0.0.into(), "2*pi".into()],
            sides: FormulaSides {
                u: Some(FormulaSeam::Periodic),
                v: Some(FormulaSeam::Periodic),
                ..FormulaSides::default()
            },
            parameters: BTreeMap::from([("R".into(), 1.0), ("r".into(), 0.4), ("n".into(), 2.0)]),
        };
        match Formula::new(source) {
            Ok(f) => f,
            Err(e) => unreachable!("the example formula is valid: {e}"),
        }
    }

    fn kinds(&self) -> [Kind; 4] {
        self.source.sides.kinds()
    }

    fn jets(&self, u: f64, v: f64) -> [Jet; 4] {
        self.shared.run(Jet::u(u), Jet::v(v))
    }
}

impl Parametric for Formula {
    fn patch_count(&self) -> usize {
        1
    }

    fn domain(&self, _: usize) -> Domain {
        sides::domain(self.ranges, self.kinds())
    }

    fn eval(&self, _: usize, u: f64, v: f64) -> Eval4 {
        Eval4::from_jets(self.jets(u, v))
    }

    fn point(&self, _: usize, u: f64, v: f64) -> DVec4 {
        DVec4::from_array(self.shared.run(u, v))
    }

    fn enclose(&self, _: usize, u: Interval, v: Interval) -> [Jet<Interval>; 4] {
        self.shared.run(Jet::u(u), Jet::v(v))
    }

    fn topology(&self) -> Topology {
        sides::topology(self.kinds())
    }

    /// Evaluates the surface on a grid of the domain: points must be finite (and within
    /// [`MAX_COORDINATE`]), derivatives finite inside the domain, bends within
    /// [`FORMULA_BEND`], and glued sides and poles must meet.
    ///
    /// [`MAX_COORDINATE`]: crate::limits::MAX_COORDINATE
    /// [`FORMULA_BEND`]: crate::limits::FORMULA_BEND
    fn check(&self) -> Result<(), FieldError> {
        let grid = self.check_grid();
        self.check_points(&grid)?;
        self.check_derivatives(&grid)?;
        let diagonal = Formula::diagonal(&grid);
        if diagonal <= 0.0 {
            return Err(FieldError::new(
                "x",
                "the four formulas are constant on the domain: the surface is a single point",
            ));
        }
        self.check_bend(&grid, diagonal)?;
        self.check_sides(diagonal)
    }

    fn min_cells(&self) -> [usize; 2] {
        sides::min_cells(self.kinds())
    }
}

/// A parameter's name: an identifier that is not u, v, pi, e or a function.
fn check_parameter_name(name: &str) -> Result<(), String> {
    let mut chars = name.chars();
    let ok = chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_');
    if !ok {
        return Err(format!(
            "`{}` is not a name: a parameter's name starts with a letter or `_` and has only ASCII letters, digits and `_`",
            shorten(name)
        ));
    }
    if ["u", "v", "pi", "e"].contains(&name) || function(name).is_some() {
        return Err(format!(
            "`{name}` is a name of the formula language (u, v, pi, e and the functions); choose another"
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::{KleinBottle, ProjectivePlane};
    use super::*;
    use std::f64::consts::{FRAC_PI_2, PI, TAU};

    // The helpers are shared with the tests of the files beside this one.
    pub(super) fn params(list: &[(&str, f64)]) -> BTreeMap<String, f64> {
        list.iter().map(|(n, x)| (n.to_string(), *x)).collect()
    }

    pub(super) fn value(text: &str, u: f64, v: f64, p: &[(&str, f64)]) -> f64 {
        match Program::compile(text, &params(p)) {
            Ok(program) => program.run(u, v),
            Err(e) => panic!("{text}: {e}"),
        }
    }

    pub(super) fn compile_error(text: &str, p: &[(&str, f64)]) -> String {
        match Program::compile(text, &params(p)) {
            Ok(_) => panic!("`{text}` compiled"),
            Err(e) => e,
        }
    }

    pub(super) fn source(xyzw: [&str; 4], u: [f64; 2], v: [f64; 2]) -> FormulaSource {
        FormulaSource {
            x: xyzw[0].into(),
            y: xyzw[1].into(),
            z: xyzw[2].into(),
            w: xyzw[3].into(),
            u: u.map(Bound::from),
            v: v.map(Bound::from),
            sides: FormulaSides::default(),
            parameters: BTreeMap::new(),
        }
    }

    pub(super) fn formula(s: FormulaSource) -> Formula {
        match Formula::new(s) {
            Ok(f) => f,
            Err(e) => panic!("{e}"),
        }
    }

    pub(super) fn check_error(s: FormulaSource) -> FieldError {
        match formula(s).check() {
            Ok(()) => panic!("the check passed"),
            Err(e) => e,
        }
    }

    /// Exact derivatives against fourth-order finite differences, as tests/surfaces.rs
    /// does for the catalogue.
    fn assert_derivatives_match(f: &Formula) {
        let d = f.domain(0);
        let (hu, hv) = ((d.u[1] - d.u[0]) * 2e-4, (d.v[1] - d.v[0]) * 2e-4);
        for k in 1..12 {
            let (a, b) = (k as f64 / 12.0, ((k * 7) % 12) as f64 / 12.0 + 0.04);
            let (u, v) = (
                d.u[0] + (d.u[1] - d.u[0]) * a,
                d.v[0] + (d.v[1] - d.v[0]) * b,
            );
            let p = |i: i32, j: i32| f.point(0, u + i as f64 * hu, v + j as f64 * hv);
            let d1 = |g: &dyn Fn(i32) -> DVec4, h: f64| {
                (-g(2) + g(1) * 8.0 - g(-1) * 8.0 + g(-2)) / (12.0 * h)
            };
            let d2 = |g: &dyn Fn(i32) -> DVec4, h: f64| {
                (-g(2) + g(1) * 16.0 - g(0) * 30.0 + g(-1) * 16.0 - g(-2)) / (12.0 * h * h)
            };
            let fd = [
                d1(&|i| p(i, 0), hu),
                d1(&|j| p(0, j), hv),
                d2(&|i| p(i, 0), hu),
                d1(&|i| d1(&|j| p(i, j), hv), hu),
                d2(&|j| p(0, j), hv),
            ];
            let e = f.eval(0, u, v);
            for (n, (x, y)) in [e.du, e.dv, e.duu, e.duv, e.dvv].iter().zip(fd).enumerate() {
                let rel = (*x - y).length() / x.length().max(1.0);
                assert!(
                    rel < 1e-6,
                    "at ({u}, {v}) derivative {n}: {x} against {y} ({rel:e})"
                );
            }
        }
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let mut s = source(
            [
                "tan(u/3)*cosh(v) + atan2(v, u + 2)",
                "asin(u/4)*exp(-v^2) + acos(v/3)/sqrt(u + 1)",
                "log(2 + sin(u*v))*tanh(v - u) + atan(u)^3",
                "(1 + u)^(v/2) + min(u, 2*v)^2 + max(u, v) + abs(u - 3) + sinh(v)^-1 + u^2.5",
            ],
            [0.2, 1.2],
            [0.3, 1.1],
        );
        s.parameters = params(&[("k", 2.0)]);
        assert_derivatives_match(&formula(s));
        assert_derivatives_match(&Formula::example());
    }

    fn same_surface(f: &Formula, s: &dyn Parametric) {
        assert_eq!(f.domain(0), s.domain(0));
        assert_eq!(f.topology(), s.topology());
        assert_eq!(f.min_cells(), s.min_cells());
        let d = s.domain(0);
        for i in 0..=20 {
            for j in 0..=20 {
                let u = d.u[0] + (d.u[1] - d.u[0]) * i as f64 / 20.0;
                let v = d.v[0] + (d.v[1] - d.v[0]) * j as f64 / 20.0;
                let (a, b) = (f.eval(0, u, v), s.eval(0, u, v));
                for (x, y) in [(a.p, b.p), (a.du, b.du), (a.dv, b.dv), (a.duu, b.duu)]
                    .into_iter()
                    .chain([(a.duv, b.duv), (a.dvv, b.dvv), (f.point(0, u, v), b.p)])
                {
                    assert!((x - y).length() < 1e-12, "at ({u}, {v}): {x} against {y}");
                }
            }
        }
        assert_eq!(f.check(), Ok(()));
    }

    #[test]
    fn the_classical_surfaces_as_formulas_are_the_built_in_ones() {
        let mut torus = source(
            ["cos(u)", "sin(u)", "cos(v)", "sin(v)"],
            [0.0, TAU],
            [0.0, TAU],
        );
        torus.sides.u = Some(FormulaSeam::Periodic);
        torus.sides.v = Some(FormulaSeam::Periodic);
        same_surface(&formula(torus), &super::super::FlatTorus::default());

        let mut klein = source(
            [
                "(R + r*cos(v))*cos(u)",
                "(R + r*cos(v))*sin(u)",
                "r*sin(v)*cos(u/2)",
                "r*sin(v)*sin(u/2)",
            ],
            [0.0, TAU],
            [0.0, TAU],
        );
        klein.parameters = params(&[("R", 1.0), ("r", 0.5)]);
        klein.sides.u = Some(FormulaSeam::Flip);
        klein.sides.v = Some(FormulaSeam::Periodic);
        same_surface(&formula(klein), &KleinBottle::default());

        let mut plane = source(
            [
                "cos(u)*(sin(u)*cos(v))",
                "cos(u)*(sin(u)*sin(v))",
                "(sin(u)*cos(v))^2 - (sin(u)*sin(v))^2",
                "2*(sin(u)*cos(v))*(sin(u)*sin(v))",
            ],
            [0.0, FRAC_PI_2],
            [0.0, TAU],
        );
        plane.sides.u_min = Some(FormulaEdge::Pole);
        plane.sides.u_max = Some(FormulaEdge::HalfTurn);
        plane.sides.v = Some(FormulaSeam::Periodic);
        same_surface(&formula(plane), &ProjectivePlane::default());
    }

    #[test]
    fn a_sphere_with_two_poles_checks_and_counts() {
        let mut sphere = source(
            ["sin(u)*cos(v)", "sin(u)*sin(v)", "cos(u)", "0"],
            [0.0, PI],
            [0.0, TAU],
        );
        sphere.sides = FormulaSides {
            u_min: Some(FormulaEdge::Pole),
            u_max: Some(FormulaEdge::Pole),
            v: Some(FormulaSeam::Periodic),
            ..FormulaSides::default()
        };
        let f = formula(sphere);
        assert_eq!(f.check(), Ok(()));
        assert_eq!(f.topology().euler_characteristic, Some(2));
        assert_eq!(f.min_cells(), [4, 4]);
    }

    #[test]
    fn garbage_never_panics() {
        let hostile = [
            "",
            " ",
            "(((((",
            ")",
            "u^",
            "^u",
            "1e999",
            "1e",
            ".",
            "..5",
            "1..2",
            ",",
            "sin(,)",
            "min(u,)",
            "atan2(u,v,)",
            "u,v",
            "()",
            "sin()",
            "\u{1F600}",
            "é + u",
            "u\u{0}v",
            "sin(u)^1e9",
            "1/(u-u)",
            "sqrt(-1-u^2)",
            "log(u-u)",
            "asin(2+u)",
            "(u-u)^-1",
            "(u-u)^-0.5",
            "(-1-u)^0.5",
            "(-1-u)^v",
            "exp(1e5*u)",
            "u^1e6",
            "sin(1e300*u)",
            "1e308*1e308*u",
            "pi(u)",
            "e^e^e^e",
            "u/0",
            "0/0",
            "--------u",
            "+",
            "u++v",
            "u**v",
            "2 3",
            "sin u",
            "_",
            "u_",
            "a",
        ];
        let long_parens = "(".repeat(10_000);
        let long_names = "x".repeat(5000);
        let many = ["(u"; 2000].join("+");
        let extra = [long_parens.as_str(), long_names.as_str(), many.as_str()];
        for text in hostile.iter().chain(&extra) {
            let s = source([text, "u", "v", "0"], [0.0, 1.0], [0.0, 1.0]);
            if let Ok(f) = Formula::new(s) {
                let _ = f.check();
                let _ = f.eval(0, 0.5, 0.5);
                let _ = f.point(0, 0.5, 0.5);
            }
        }
    }

    #[test]
    fn fields_are_checked_when_the_surface_is_made() {
        let err = |s: FormulaSource| match Formula::new(s) {
            Ok(_) => panic!("accepted"),
            Err(e) => e,
        };
        let mut s = source(["u", "v", "0", "0"], [1.0, 1.0], [0.0, 1.0]);
        assert_eq!(err(s.clone()).field, "u");
        s.u = [0.0.into(), 1.0.into()];
        s.v = [0.0.into(), f64::INFINITY.into()];
        assert_eq!(err(s.clone()).field, "v");
        // A range's ends as formulas: constants and parameters, not u or v.
        s.v = [0.0.into(), "2*pi/n".into()];
        s.parameters = params(&[("n", 4.0)]);
        let f = Formula::new(s.clone()).unwrap();
        assert_eq!(f.domain(0).v, [0.0, TAU / 4.0]);
        s.v = [0.0.into(), "1 + u".into()];
        let e = err(s.clone());
        assert_eq!(e.field, "v[1]");
        assert!(e.message.contains("not u or v"), "{}", e.message);
        s.v = [0.0.into(), "2*pii".into()];
        let e = err(s.clone());
        assert_eq!(e.field, "v[1]");
        assert!(e.message.contains("`pi`"), "{}", e.message);
        s.v = [0.0.into(), 1.0.into()];
        s.parameters = BTreeMap::new();
        for bad in ["pi", "u", "sin", "2x", "a b", ""] {
            let mut t = s.clone();
            t.parameters = params(&[(bad, 1.0)]);
            assert_eq!(err(t).field, format!("parameters.{bad}"));
        }
        let mut t = s.clone();
        t.parameters = params(&[("a", f64::NAN)]);
        assert!(err(t).message.contains("finite"));
        let mut t = s.clone();
        t.sides.u = Some(FormulaSeam::Periodic);
        t.sides.u_max = Some(FormulaEdge::Pole);
        let e = err(t);
        assert_eq!(e.field, "sides.u_max");
        assert!(e.message.contains("either `u`"), "{e}");
        let mut t = s.clone();
        t.w = "sin(".into();
        assert_eq!(err(t).field, "w");
    }

    #[test]
    fn a_scene_entry_reads_checks_and_writes_back() {
        use super::super::Surface;
        let json = serde_json::json!({
            "type": "formula",
            "x": "cos(u)", "y": "sin(u)", "z": "a*cos(v)", "w": "a*sin(v)",
            "u": [0.0, TAU], "v": [0.0, TAU],
            "sides": {"u": "periodic", "v": "periodic"},
            "parameters": {"a": 1.5}
        });
        let s: Surface = serde_json::from_value(json.clone()).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(s.type_name(), "formula");
        assert_eq!(s.check(), Ok(()));
        assert_eq!(s.topology().euler_characteristic, Some(0));
        assert_eq!(serde_json::to_value(&s).ok(), Some(json.clone()));
        let mut broken = json.clone();
        broken["x"] = "cos(u".into();
        let e = serde_json::from_value::<Surface>(broken)
            .err()
            .map(|e| e.to_string());
        let e = e.unwrap_or_default();
        assert!(
            e.starts_with("x: cannot read the formula at character 6"),
            "{e}"
        );
        let mut broken = json.clone();
        broken["sides"]["u_min"] = "pole".into();
        let e = serde_json::from_value::<Surface>(broken)
            .err()
            .map(|e| e.to_string());
        assert!(
            e.unwrap_or_default()
                .starts_with("sides.u_min: give either")
        );
        let mut broken = json.clone();
        broken["colour"] = "red".into();
        let e = serde_json::from_value::<Surface>(broken)
            .err()
            .map(|e| e.to_string());
        assert!(e.unwrap_or_default().contains("unknown field `colour`"));
        let mut broken = json.clone();
        broken["sides"]["u"] = "twisted".into();
        let e = serde_json::from_value::<Surface>(broken)
            .err()
            .map(|e| e.to_string());
        assert!(
            e.unwrap_or_default()
                .starts_with("sides.u: unknown variant `twisted`")
        );
        let mut broken = json;
        broken.as_object_mut().map(|m| m.remove("w"));
        let e = serde_json::from_value::<Surface>(broken)
            .err()
            .map(|e| e.to_string());
        assert!(e.unwrap_or_default().contains("missing field `w`"));
    }

    #[test]
    fn the_example_is_a_valid_torus() {
        let f = Formula::example();
        assert_eq!(f.check(), Ok(()));
        assert_eq!(f.topology().euler_characteristic, Some(0));
        assert!(f.topology().orientable);
    }
}
