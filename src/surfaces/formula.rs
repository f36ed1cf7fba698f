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

use super::{Domain, Eval4, Glue, Jet, Parametric, Side, SideRule, Topology};
use crate::limits::{
    FORMULA_BEND, FORMULA_DEPTH, FORMULA_EXPONENT, FORMULA_GLUE, FORMULA_LENGTH, FieldError,
    MAX_COORDINATE, shorten,
};
use glam::DVec4;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::f64::consts::{E, PI};
use std::ops::{Add, Div, Mul, Neg, Sub};

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

    /// The rule of each side, in the order of [`Side::ALL`].
    fn kinds(&self) -> [Kind; 4] {
        let pair = |both: Option<FormulaSeam>, lo: Option<FormulaEdge>, hi: Option<FormulaEdge>| {
            let one = |e: Option<FormulaEdge>| match e {
                None | Some(FormulaEdge::Open) => Kind::Open,
                Some(FormulaEdge::Pole) => Kind::Pole,
                Some(FormulaEdge::HalfTurn) => Kind::HalfTurn,
            };
            match both {
                Some(FormulaSeam::Periodic) => [Kind::Periodic; 2],
                Some(FormulaSeam::Flip) => [Kind::Flip; 2],
                Some(FormulaSeam::Open) => [Kind::Open; 2],
                None => [one(lo), one(hi)],
            }
        };
        let [u0, u1] = pair(self.u, self.u_min, self.u_max);
        let [v0, v1] = pair(self.v, self.v_min, self.v_max);
        [u0, u1, v0, v1]
    }

    /// The key that set the rule of `side`, as a path from the surface.
    fn field(&self, side: Side) -> &'static str {
        match side {
            Side::U0 | Side::U1 if self.u.is_some() => "sides.u",
            Side::V0 | Side::V1 if self.v.is_some() => "sides.v",
            Side::U0 => "sides.u_min",
            Side::U1 => "sides.u_max",
            Side::V0 => "sides.v_min",
            Side::V1 => "sides.v_max",
        }
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

/// The rule of one side once the keys are resolved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Open,
    Pole,
    HalfTurn,
    Periodic,
    Flip,
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
            if !value.is_finite() {
                return Err(FieldError::new(
                    field,
                    format!("must be a finite number, got {value}"),
                ));
            }
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

    /// The points of the check grid with their jets: a regular grid with the sides, then
    /// the same grid shifted inside its cells by irrational shares, so that a frequency
    /// that fits the regular grid (sin(1e5 u) over [0, 2π] is 0 at all its points) does
    /// not hide from the check.
    fn check_grid(&self) -> Vec<(f64, f64, [Jet; 4])> {
        let [du, dv] = self.ranges;
        let cells = (CHECK_GRID - 1) as f64;
        let at = |r: [f64; 2], i: usize, shift: f64| {
            if i == CHECK_GRID - 1 && shift == 0.0 {
                r[1]
            } else {
                r[0] + (r[1] - r[0]) * (i as f64 + shift) / cells
            }
        };
        let mut out = Vec::with_capacity(2 * CHECK_GRID * CHECK_GRID);
        for (n, su, sv) in [
            (CHECK_GRID, 0.0, 0.0),
            (CHECK_GRID - 1, GRID_SHIFT[0], GRID_SHIFT[1]),
        ] {
            for j in 0..n {
                for i in 0..n {
                    let (u, v) = (at(du, i, su), at(dv, j, sv));
                    out.push((u, v, self.jets(u, v)));
                }
            }
        }
        out
    }

    /// Finite points within [`MAX_COORDINATE`] everywhere on the grid.
    fn check_points(&self, grid: &[(f64, f64, [Jet; 4])]) -> Result<(), FieldError> {
        for (u, v, jets) in grid {
            for (k, j) in jets.iter().enumerate() {
                if !j.v.is_finite() {
                    let why = self.programs[k]
                        .first_failure(*u, *v, false)
                        .unwrap_or_else(|| "the value is not finite".into());
                    return Err(FieldError::new(
                        COMPONENTS[k],
                        format!("not finite at (u, v) = ({u}, {v}): {why}"),
                    ));
                }
                if j.v.abs() > MAX_COORDINATE {
                    return Err(FieldError::new(
                        COMPONENTS[k],
                        format!(
                            "reaches {:e} at (u, v) = ({u}, {v}), beyond the {MAX_COORDINATE:e} a coordinate may reach",
                            j.v
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Finite derivatives inside the domain; on its sides, finite derivatives just inside
    /// (where the sampler takes a vertex's tangents when those at the side are not finite).
    fn check_derivatives(&self, grid: &[(f64, f64, [Jet; 4])]) -> Result<(), FieldError> {
        let [[u0, u1], [v0, v1]] = self.ranges;
        let finite = |j: &Jet| {
            [j.du, j.dv, j.duu, j.duv, j.dvv]
                .iter()
                .all(|d| d.is_finite())
        };
        for (u, v, jets) in grid {
            for (k, j) in jets.iter().enumerate() {
                if finite(j) {
                    continue;
                }
                let on_side = *u == u0 || *u == u1 || *v == v0 || *v == v1;
                let inside = on_side && {
                    let (cu, cv) = ((u0 + u1) / 2.0, (v0 + v1) / 2.0);
                    let (iu, iv) = (u + (cu - u) * 1e-6, v + (cv - v) * 1e-6);
                    finite(&self.programs[k].run(Jet::u(iu), Jet::v(iv)))
                };
                if inside {
                    continue;
                }
                let why = self.programs[k]
                    .first_failure(*u, *v, true)
                    .unwrap_or_else(|| "a derivative is not finite".into());
                let place = if on_side {
                    "on the side of the domain, and not just inside it either"
                } else {
                    "inside the domain"
                };
                return Err(FieldError::new(
                    COMPONENTS[k],
                    format!(
                        "its derivatives are not finite at (u, v) = ({u}, {v}), {place}: {why}"
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The diagonal of the grid's bounding box.
    fn diagonal(grid: &[(f64, f64, [Jet; 4])]) -> f64 {
        let (mut lo, mut hi) = (DVec4::splat(f64::INFINITY), DVec4::splat(f64::NEG_INFINITY));
        for (_, _, j) in grid {
            let p = DVec4::new(j[0].v, j[1].v, j[2].v, j[3].v);
            lo = lo.min(p);
            hi = hi.max(p);
        }
        (hi - lo).length()
    }

    /// Second derivatives times the squared parameter extents within [`FORMULA_BEND`]
    /// bounding diagonals.
    fn check_bend(&self, grid: &[(f64, f64, [Jet; 4])], diagonal: f64) -> Result<(), FieldError> {
        let lu = self.ranges[0][1] - self.ranges[0][0];
        let lv = self.ranges[1][1] - self.ranges[1][0];
        for (u, v, jets) in grid {
            for (k, j) in jets.iter().enumerate() {
                let c = COMPONENTS[k];
                let bends = [
                    (
                        j.duu,
                        lu * lu,
                        format!("∂²{c}/∂u²"),
                        "the square of the u range",
                    ),
                    (
                        j.duv,
                        lu * lv,
                        format!("∂²{c}/∂u∂v"),
                        "the product of the u and v ranges",
                    ),
                    (
                        j.dvv,
                        lv * lv,
                        format!("∂²{c}/∂v²"),
                        "the square of the v range",
                    ),
                ];
                for (d, extent, name, ranges) in bends {
                    let bend = d.abs() * extent / diagonal;
                    // Non-finite derivatives were judged by `check_derivatives`.
                    if bend.is_finite() && bend > FORMULA_BEND {
                        return Err(FieldError::new(
                            c,
                            format!(
                                "bends too sharply to be sampled at (u, v) = ({u}, {v}): {name} = {d:e}, times {ranges} ({extent:.3e}), is {bend:.1e} times the surface's bounding diagonal ({diagonal:.3e}), more than {FORMULA_BEND:e}; narrow the ranges or smooth the formula"
                            ),
                        ));
                    }
                }
            }
        }
        Ok(())
    }

    /// Glued points meet and poles are points, at [`GLUE_SAMPLES`] points of each side.
    fn check_sides(&self, diagonal: f64) -> Result<(), FieldError> {
        let d = self.domain(0);
        let tolerance = FORMULA_GLUE * diagonal;
        for side in Side::ALL {
            let field = self.source.sides.field(side);
            for i in 0..GLUE_SAMPLES {
                let sigma = i as f64 / (GLUE_SAMPLES - 1) as f64;
                let here = d.side_point(side, sigma);
                let (there, what) = match d.side(side) {
                    SideRule::Open => break,
                    SideRule::Pole => (d.side_point(side, 0.0), "the pole's first point"),
                    SideRule::Glued(pieces) => {
                        let Some(g) = pieces.iter().find(|g| g.from <= sigma && sigma <= g.to)
                        else {
                            continue;
                        };
                        (
                            d.side_point(g.side, g.map(sigma)),
                            "the point it is glued to",
                        )
                    }
                };
                let gap = self
                    .point(0, here.0, here.1)
                    .distance(self.point(0, there.0, there.1));
                if gap > tolerance || gap.is_nan() {
                    return Err(FieldError::new(
                        field,
                        format!(
                            "the side's points do not meet: (u, v) = ({}, {}) is {gap:.3e} away from {what}, (u, v) = ({}, {}), more than {FORMULA_GLUE:e} of the bounding diagonal ({diagonal:.3e})",
                            here.0, here.1, there.0, there.1
                        ),
                    ));
                }
            }
        }
        Ok(())
    }
}

/// Points per axis of the grid [`Formula`]'s check evaluates (sides included).
const CHECK_GRID: usize = 65;

/// Where in its cell the shifted check grid puts its points: the golden section, far from
/// any simple fraction.
const GRID_SHIFT: [f64; 2] = [0.381_966_011_250_105, 0.618_033_988_749_895];

/// Points of each glued side or pole the check compares.
const GLUE_SAMPLES: usize = 17;

impl Parametric for Formula {
    fn patch_count(&self) -> usize {
        1
    }

    fn domain(&self, _: usize) -> Domain {
        let kinds = self.kinds();
        let mut d = Domain::open(self.ranges[0], self.ranges[1]);
        for (side, kind) in Side::ALL.into_iter().zip(kinds) {
            let partner = match side {
                Side::U0 => Side::U1,
                Side::U1 => Side::U0,
                Side::V0 => Side::V1,
                Side::V1 => Side::V0,
            };
            let half = |from: f64, offset: f64| Glue {
                from,
                to: from + 0.5,
                patch: 0,
                side,
                offset,
                reversed: false,
            };
            let rule = match kind {
                Kind::Open => SideRule::Open,
                Kind::Pole => SideRule::Pole,
                Kind::HalfTurn => SideRule::Glued(vec![half(0.0, 0.5), half(0.5, -0.5)]),
                Kind::Periodic => SideRule::Glued(vec![Glue::whole(0, partner, false)]),
                Kind::Flip => SideRule::Glued(vec![Glue::whole(0, partner, true)]),
            };
            d = d.with(side, rule);
        }
        d
    }

    fn eval(&self, _: usize, u: f64, v: f64) -> Eval4 {
        Eval4::from_jets(self.jets(u, v))
    }

    fn point(&self, _: usize, u: f64, v: f64) -> DVec4 {
        DVec4::from_array(self.shared.run(u, v))
    }

    fn topology(&self) -> Topology {
        topology(self.kinds())
    }

    /// Evaluates the surface on a grid of the domain: points must be finite (and within
    /// [`MAX_COORDINATE`]), derivatives finite inside the domain, bends within
    /// [`FORMULA_BEND`], and glued sides and poles must meet.
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

    /// 4 cells across a seam or a pole as the catalogue, 6 along a side glued to itself by
    /// a half turn (the projective plane's equator), which 4 cells would fold onto 2
    /// vertices.
    fn min_cells(&self) -> [usize; 2] {
        let k = self.kinds();
        let along = |a: Kind, b: Kind| {
            if a == Kind::HalfTurn || b == Kind::HalfTurn {
                6
            } else {
                4
            }
        };
        [along(k[2], k[3]), along(k[0], k[1])]
    }
}

/// Closedness, orientability and Euler characteristic of the rectangle under the side
/// rules, counted on its cell complex: 4 corners, one edge per side (two, with a vertex at
/// the middle, for a half turn), one face; glued edges and their ends are identified, a
/// pole's edge collapses and its ends become one vertex.
fn topology(kinds: [Kind; 4]) -> Topology {
    // Corners: 0 = (u0, v0), 1 = (u1, v0), 2 = (u0, v1), 3 = (u1, v1); the middle of side
    // s is vertex 4 + s. Side s runs (with its coordinate) from ENDS[s].0 to ENDS[s].1; its
    // edges are 2s (the first half, or the whole side) and 2s + 1 (the second half).
    const ENDS: [(usize, usize); 4] = [(0, 2), (1, 3), (0, 1), (2, 3)];
    let mut vertex: Vec<usize> = (0..8).collect();
    let mut edge: Vec<usize> = (0..8).collect();
    fn find(p: &mut [usize], mut a: usize) -> usize {
        while p[a] != a {
            p[a] = p[p[a]];
            a = p[a];
        }
        a
    }
    fn union(p: &mut [usize], a: usize, b: usize) {
        let (a, b) = (find(p, a), find(p, b));
        p[a] = b;
    }
    let mut vertices = vec![0, 1, 2, 3];
    let mut edges = Vec::new();
    for (s, kind) in kinds.iter().enumerate() {
        let (a, b) = ENDS[s];
        match kind {
            Kind::Open => edges.push(2 * s),
            Kind::Pole => union(&mut vertex, a, b),
            Kind::HalfTurn => {
                vertices.push(4 + s);
                union(&mut vertex, a, 4 + s);
                union(&mut vertex, 4 + s, b);
                union(&mut edge, 2 * s, 2 * s + 1);
                edges.extend([2 * s, 2 * s + 1]);
            }
            Kind::Periodic | Kind::Flip => {
                edges.push(2 * s);
                // The first side of the pair glues both.
                if s % 2 == 0 {
                    let (c, d) = ENDS[s + 1];
                    let (c, d) = if *kind == Kind::Flip { (d, c) } else { (c, d) };
                    union(&mut vertex, a, c);
                    union(&mut vertex, b, d);
                    union(&mut edge, 2 * s, 2 * s + 2);
                }
            }
        }
    }
    let count = |p: &mut Vec<usize>, items: &[usize]| {
        let mut roots: Vec<usize> = items.iter().map(|&i| find(p, i)).collect();
        roots.sort_unstable();
        roots.dedup();
        roots.len() as i64
    };
    let closed = !kinds.contains(&Kind::Open);
    let v = count(&mut vertex, &vertices);
    let e = count(&mut edge, &edges);
    Topology {
        closed,
        orientable: !kinds.contains(&Kind::Flip) && !kinds.contains(&Kind::HalfTurn),
        euler_characteristic: closed.then_some(v - e + 1),
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

// ---------------------------------------------------------------------------------------
// The expression language.

/// The functions a formula may call.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Fun {
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Atan2,
    Sinh,
    Cosh,
    Tanh,
    Exp,
    Log,
    Sqrt,
    Abs,
    Min,
    Max,
}

const FUNCTIONS: [(&str, Fun); 16] = [
    ("sin", Fun::Sin),
    ("cos", Fun::Cos),
    ("tan", Fun::Tan),
    ("asin", Fun::Asin),
    ("acos", Fun::Acos),
    ("atan", Fun::Atan),
    ("atan2", Fun::Atan2),
    ("sinh", Fun::Sinh),
    ("cosh", Fun::Cosh),
    ("tanh", Fun::Tanh),
    ("exp", Fun::Exp),
    ("log", Fun::Log),
    ("sqrt", Fun::Sqrt),
    ("abs", Fun::Abs),
    ("min", Fun::Min),
    ("max", Fun::Max),
];

fn function(name: &str) -> Option<Fun> {
    FUNCTIONS.iter().find(|(n, _)| *n == name).map(|(_, f)| *f)
}

impl Fun {
    fn arity(self) -> usize {
        match self {
            Fun::Atan2 | Fun::Min | Fun::Max => 2,
            _ => 1,
        }
    }

    fn name(self) -> &'static str {
        FUNCTIONS
            .iter()
            .find(|(_, f)| *f == self)
            .map_or("?", |(n, _)| n)
    }
}

/// One instruction of a compiled formula, run on a stack.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Op {
    Const(f64),
    U,
    V,
    Neg,
    Add,
    Sub,
    Mul,
    Div,
    /// The base to a constant integer power.
    PowI(i32),
    /// The base to a constant real power.
    PowF(f64),
    /// x^y for a varying exponent: exp(y ln x).
    Pow,
    Call(Fun),
}

impl Op {
    fn arity(self) -> usize {
        match self {
            Op::Const(_) | Op::U | Op::V => 0,
            Op::Neg | Op::PowI(_) | Op::PowF(_) => 1,
            Op::Add | Op::Sub | Op::Mul | Op::Div | Op::Pow => 2,
            Op::Call(f) => f.arity(),
        }
    }
}

/// What a formula computes with: f64 for points, [`Jet`] for derivatives. Both take the
/// same steps, so that a point is bit for bit the value of its jet.
trait Number:
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

impl Number for Jet {
    fn constant(x: f64) -> Self {
        Jet::constant(x)
    }
    fn int_power(self, n: i32) -> Self {
        self.powi(n)
    }
    fn real_power(self, k: f64) -> Self {
        self.powf(k)
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
        Jet {
            v: self.v / k,
            du: self.du / k,
            dv: self.dv / k,
            duu: self.duu / k,
            duv: self.duv / k,
            dvv: self.dvv / k,
        }
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
            Fun::Abs => a.abs(),
            Fun::Atan2 | Fun::Min | Fun::Max => Jet::constant(f64::NAN),
        }
    }
    fn call2(f: Fun, a: Self, b: Self) -> Self {
        match f {
            Fun::Atan2 => a.atan2(b),
            Fun::Min => a.min(b),
            Fun::Max => a.max(b),
            _ => Jet::constant(f64::NAN),
        }
    }
}

/// Runs one instruction on the stack `s` whose first `sp` entries are live.
fn exec<T: Number>(op: Op, s: &mut [T], sp: &mut usize, u: T, v: T) {
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

/// A compiled formula: a postfix program with every name resolved (u and v to their
/// instructions, parameters and constants to numbers, constant parts folded), so that a
/// run does no string work and no recursion.
#[derive(Clone, Debug)]
struct Program {
    ops: Vec<Op>,
    /// The characters `[start, end)` of the source each instruction computes.
    spans: Vec<(usize, usize)>,
    /// The source's characters, for messages.
    text: Vec<char>,
    /// The deepest the stack gets.
    depth: usize,
}

/// The four programs as one list of nodes, each computed once for all four coordinates
/// (`cos(u)` in x and in y is one node: the built-in surfaces share such values by hand),
/// in an order where every node reads earlier ones. An operation with a constant operand
/// becomes one on the other operand alone (`r*cos(v)` scales, as the built-in surfaces
/// write it), which over [`Jet`]s skips the derivatives of the constant.
#[derive(Clone, Debug)]
struct Shared {
    /// Each node and the nodes it reads (as many as it takes).
    nodes: Vec<(Node, [u32; 2])>,
    /// The nodes of x, y, z and w.
    outputs: [u32; 4],
}

/// A node of [`Shared`].
#[derive(Clone, Copy, Debug)]
enum Node {
    /// An instruction of the programs.
    Op(Op),
    /// The operand times a constant.
    Scale(f64),
    /// The operand plus a constant.
    Shift(f64),
    /// The operand divided by a constant.
    Over(f64),
}

impl Node {
    /// How many nodes it reads.
    fn arity(self) -> usize {
        match self {
            Node::Op(op) => op.arity(),
            Node::Scale(_) | Node::Shift(_) | Node::Over(_) => 1,
        }
    }
}

impl Shared {
    fn new(programs: &[Program; 4]) -> Shared {
        use std::collections::HashMap;
        let key = |node: Node| -> (u8, u64) {
            match node {
                Node::Op(Op::Const(x)) => (0, x.to_bits()),
                Node::Op(Op::U) => (1, 0),
                Node::Op(Op::V) => (2, 0),
                Node::Op(Op::Neg) => (3, 0),
                Node::Op(Op::Add) => (4, 0),
                Node::Op(Op::Sub) => (5, 0),
                Node::Op(Op::Mul) => (6, 0),
                Node::Op(Op::Div) => (7, 0),
                Node::Op(Op::PowI(n)) => (8, u64::from(n as u32)),
                Node::Op(Op::PowF(k)) => (9, k.to_bits()),
                Node::Op(Op::Pow) => (10, 0),
                Node::Op(Op::Call(f)) => (11, f as u64),
                Node::Scale(k) => (12, k.to_bits()),
                Node::Shift(k) => (13, k.to_bits()),
                Node::Over(k) => (14, k.to_bits()),
            }
        };
        // Nodes 0 and 1 are u and v: a run starts with them in its registers.
        let mut nodes: Vec<(Node, [u32; 2])> =
            vec![(Node::Op(Op::U), [0, 0]), (Node::Op(Op::V), [0, 0])];
        let mut seen: HashMap<((u8, u64), [u32; 2]), u32> = HashMap::from([
            ((key(nodes[0].0), [0, 0]), 0),
            ((key(nodes[1].0), [0, 0]), 1),
        ]);
        let mut outputs = [0; 4];
        for (k, program) in programs.iter().enumerate() {
            let mut stack: Vec<u32> = Vec::with_capacity(program.depth);
            for op in &program.ops {
                let mut args = [0; 2];
                for i in (0..op.arity()).rev() {
                    args[i] = stack.pop().unwrap_or_default();
                }
                let constant = |id: u32| match nodes.get(id as usize) {
                    Some((Node::Op(Op::Const(c)), _)) => Some(*c),
                    _ => None,
                };
                let (a, b) = (constant(args[0]), constant(args[1]));
                let node = match (op, a, b) {
                    (Op::Mul, Some(c), None) => (Node::Scale(c), [args[1], 0]),
                    (Op::Mul, None, Some(c)) => (Node::Scale(c), [args[0], 0]),
                    (Op::Add, Some(c), None) => (Node::Shift(c), [args[1], 0]),
                    (Op::Add, None, Some(c)) => (Node::Shift(c), [args[0], 0]),
                    // a - c is a + (-c), exactly.
                    (Op::Sub, None, Some(c)) => (Node::Shift(-c), [args[0], 0]),
                    (Op::Div, None, Some(c)) => (Node::Over(c), [args[0], 0]),
                    _ => (Node::Op(*op), args),
                };
                let id = *seen.entry((key(node.0), node.1)).or_insert_with(|| {
                    nodes.push(node);
                    (nodes.len() - 1) as u32
                });
                stack.push(id);
            }
            outputs[k] = stack.pop().unwrap_or_default();
        }
        // Constants folded into scale, shift and division nodes are read by no node: drop
        // what the outputs do not need, renumbering the rest.
        let mut live = vec![false; nodes.len()];
        live[..2].fill(true);
        for o in outputs {
            live[o as usize] = true;
        }
        for i in (0..nodes.len()).rev() {
            if live[i] {
                let (node, args) = nodes[i];
                for &a in &args[..node.arity()] {
                    live[a as usize] = true;
                }
            }
        }
        let mut renumber = vec![0u32; nodes.len()];
        let mut kept = Vec::with_capacity(nodes.len());
        for (i, (node, args)) in nodes.into_iter().enumerate() {
            if live[i] {
                renumber[i] = kept.len() as u32;
                kept.push((node, args.map(|a| renumber[a as usize])));
            }
        }
        Shared {
            nodes: kept,
            outputs: outputs.map(|o| renumber[o as usize]),
        }
    }

    fn run<T: Number>(&self, u: T, v: T) -> [T; 4] {
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
    /// Compiles `text`; the error is the message a [`FieldError`] carries: what is wrong,
    /// and the formula with a caret under where.
    fn compile(text: &str, parameters: &BTreeMap<String, f64>) -> Result<Program, String> {
        if text.len() > FORMULA_LENGTH {
            return Err(format!(
                "the formula is {} bytes long, more than the {FORMULA_LENGTH} a formula may have",
                text.len()
            ));
        }
        let chars: Vec<char> = text.chars().collect();
        Parser::run(&chars, parameters).map_err(|e| {
            format!(
                "cannot read the formula at character {}: {}\n{}",
                e.at + 1,
                e.message,
                caret(&chars, e.at)
            )
        })
    }

    fn run<T: Number>(&self, u: T, v: T) -> T {
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
    fn first_failure(&self, u: f64, v: f64, derivatives: bool) -> Option<String> {
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

/// Why an instruction with finite inputs gave the non-finite `out`.
fn failure(op: Op, inputs: &[f64], out: f64, snippet: &str) -> String {
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
fn caret(chars: &[char], at: usize) -> String {
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

/// A parse error: the character (0-based) and what is wrong there.
struct ParseError {
    at: usize,
    message: String,
}

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Num(f64),
    Name(String),
    Sym(char),
    End,
}

#[derive(Clone, Debug)]
struct Token {
    tok: Tok,
    /// Its first character.
    at: usize,
    /// One past its last character.
    end: usize,
}

fn lex(chars: &[char]) -> Result<Vec<Token>, ParseError> {
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

/// Recursive descent over the tokens, emitting postfix code:
///
/// ```text
/// expr    = term (("+" | "-") term)*
/// term    = unary (("*" | "/") unary)*
/// unary   = ("-" | "+") unary | power
/// power   = primary ("^" unary)?          right-associative, above unary minus
/// primary = number | name | name "(" expr ("," expr)* ")" | "(" expr ")"
/// ```
struct Parser<'a> {
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
    fn run(
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
    use super::super::{KleinBottle, ProjectivePlane};
    use super::*;
    use std::f64::consts::{FRAC_PI_2, TAU};

    fn params(list: &[(&str, f64)]) -> BTreeMap<String, f64> {
        list.iter().map(|(n, x)| (n.to_string(), *x)).collect()
    }

    fn value(text: &str, u: f64, v: f64, p: &[(&str, f64)]) -> f64 {
        match Program::compile(text, &params(p)) {
            Ok(program) => program.run(u, v),
            Err(e) => panic!("{text}: {e}"),
        }
    }

    fn compile_error(text: &str, p: &[(&str, f64)]) -> String {
        match Program::compile(text, &params(p)) {
            Ok(_) => panic!("`{text}` compiled"),
            Err(e) => e,
        }
    }

    fn source(xyzw: [&str; 4], u: [f64; 2], v: [f64; 2]) -> FormulaSource {
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

    fn formula(s: FormulaSource) -> Formula {
        match Formula::new(s) {
            Ok(f) => f,
            Err(e) => panic!("{e}"),
        }
    }

    fn check_error(s: FormulaSource) -> FieldError {
        match formula(s).check() {
            Ok(()) => panic!("the check passed"),
            Err(e) => e,
        }
    }

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
    fn topology_follows_the_side_rules() {
        use Kind::*;
        let t = |kinds| {
            let t = topology(kinds);
            (t.closed, t.orientable, t.euler_characteristic)
        };
        assert_eq!(
            t([Periodic, Periodic, Periodic, Periodic]),
            (true, true, Some(0))
        );
        assert_eq!(t([Flip, Flip, Periodic, Periodic]), (true, false, Some(0)));
        assert_eq!(t([Periodic, Periodic, Flip, Flip]), (true, false, Some(0)));
        assert_eq!(
            t([Pole, HalfTurn, Periodic, Periodic]),
            (true, false, Some(1))
        );
        assert_eq!(t([Pole, Pole, Periodic, Periodic]), (true, true, Some(2)));
        assert_eq!(t([Periodic, Periodic, Pole, Pole]), (true, true, Some(2)));
        // Both pairs flipped: the boundary word abab, a projective plane.
        assert_eq!(t([Flip, Flip, Flip, Flip]), (true, false, Some(1)));
        // Two half turns: two cross-caps, a Klein bottle.
        assert_eq!(
            t([HalfTurn, HalfTurn, Periodic, Periodic]),
            (true, false, Some(0))
        );
        assert_eq!(t([Open, Open, Periodic, Periodic]), (false, true, None));
        assert_eq!(t([Open, Open, Flip, Flip]), (false, false, None));
        assert_eq!(t([Open; 4]), (false, true, None));
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

    #[test]
    fn limits_hold_against_hostile_input() {
        let deep = "(".repeat(4000);
        assert!(compile_error(&deep, &[]).contains("deeper than 256 levels"));
        let e = compile_error(&"(".repeat(10_000), &[]);
        assert!(e.contains("10000 bytes long"), "{e}");
        let deep = format!("{}u{}", "(".repeat(300), ")".repeat(300));
        assert!(compile_error(&deep, &[]).contains("deeper than 256 levels"));
        let signs = format!("{}u", "-".repeat(300));
        assert!(compile_error(&signs, &[]).contains("deeper than 256 levels"));
        let powers = format!("{}u", "u^".repeat(300));
        assert!(compile_error(&powers, &[]).contains("deeper than 256 levels"));
        // At the limit, it parses and evaluates without recursion.
        let ok = format!("{}u{}", "(".repeat(200), ")".repeat(200));
        assert_eq!(value(&ok, 2.0, 0.0, &[]), 2.0);
        let long = "u+".repeat(2047) + "u";
        assert_eq!(value(&long, 1.0, 0.0, &[]), 2048.0);
        let e = compile_error(&"u+".repeat(3000), &[]);
        assert!(e.contains("6000 bytes long, more than the 4096"), "{e}");
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
    fn the_check_names_the_component_the_point_and_the_cause() {
        let e = check_error(source(["1/(u-u)", "u", "v", "0"], [0.0, 1.0], [0.0, 1.0]));
        assert_eq!(e.field, "x");
        assert_eq!(
            e.message,
            "not finite at (u, v) = (0, 0): `1/(u-u)` divides by zero"
        );
        let e = check_error(source(
            ["u", "sqrt(-1-u^2)", "v", "0"],
            [0.0, 1.0],
            [0.0, 1.0],
        ));
        assert_eq!(e.field, "y");
        assert_eq!(
            e.message,
            "not finite at (u, v) = (0, 0): `sqrt(-1-u^2)` takes the square root of the negative number -1"
        );
        let e = check_error(source(
            ["u", "v", "log(u - 0.5)", "0"],
            [0.0, 1.0],
            [0.0, 1.0],
        ));
        assert!(
            e.message
                .contains("`log(u - 0.5)` takes the logarithm of the negative number -0.5"),
            "{e}"
        );
        let e = check_error(source(
            ["u", "v", "0", "exp(1e6*u)"],
            [0.0, 1.0],
            [0.0, 1.0],
        ));
        assert_eq!(e.field, "w");
        assert!(
            e.message
                .contains("(0.015625, 0): `exp(1e6*u)` is infinite (it overflows)"),
            "{e}"
        );
        let e = check_error(source(
            ["u", "v", "0", "1e20*exp(30*u)"],
            [0.0, 1.0],
            [0.0, 1.0],
        ));
        assert!(
            e.message.contains("beyond the 1e30 a coordinate may reach"),
            "{e}"
        );
        // An infinite derivative inside the domain is an error; on a side it is not, since
        // the sampler takes the tangents just inside.
        let e = check_error(source(
            ["u", "v", "sqrt((u - 0.5)^2 + (v - 0.5)^2)", "0"],
            [0.0, 1.0],
            [0.0, 1.0],
        ));
        assert_eq!(e.field, "z");
        assert_eq!(
            e.message,
            "its derivatives are not finite at (u, v) = (0.5, 0.5), inside the domain: `sqrt((u - 0.5)^2 + (v - 0.5)^2)` is 0 there but its derivatives are not finite (it is not differentiable there)"
        );
        let e = check_error(source(
            ["abs(u - 0.5)^0.5", "u", "v", "0"],
            [0.0, 1.0],
            [0.0, 1.0],
        ));
        assert_eq!(e.field, "x");
        assert!(
            e.message.starts_with("its derivatives are not finite at (u, v) = (0.5, 0), on the side of the domain, and not just inside it either: `abs(u - 0.5)^0.5` is 0 there"),
            "{e}"
        );
        let f = formula(source(["sqrt(u)", "u", "v", "0"], [0.0, 1.0], [0.0, 1.0]));
        assert_eq!(f.check(), Ok(()));
        assert!(!f.eval(0, 0.0, 0.5).tangents_finite());
        let e = check_error(source(["1", "2", "0", "0*u + 0*v"], [0.0, 1.0], [0.0, 1.0]));
        assert!(e.message.contains("single point"), "{e}");
    }

    #[test]
    fn features_finer_than_the_sampler_resolves_are_rejected() {
        // sin(u)^1e9 is caught by its exponent (see the parse errors); a fast oscillation
        // by its bend on the grid.
        let e = check_error(source(
            ["sin(1e5*u)", "u", "v", "0"],
            [0.0, TAU],
            [0.0, 1.0],
        ));
        assert_eq!(e.field, "x");
        assert!(
            e.message
                .starts_with("bends too sharply to be sampled at (u, v) = ("),
            "{e}"
        );
        assert!(e.message.contains("∂²x/∂u²"), "{e}");
        // The same spike as a varying power, where the grid meets its top (a spike
        // between grid points escapes this check: hence the bound on constant exponents).
        let e = check_error(source(
            ["exp(1e9*log(sin(u)))", "u", "v", "0"],
            [0.0, PI],
            [0.0, 1.0],
        ));
        assert!(
            e.message.starts_with(&format!(
                "bends too sharply to be sampled at (u, v) = ({}, 0): ∂²x/∂u² = -1e9",
                FRAC_PI_2
            )),
            "{e}"
        );
        // A thousand oscillations are fine.
        let f = formula(source(
            ["sin(1000*u)", "u", "v", "0"],
            [0.0, TAU],
            [0.0, 1.0],
        ));
        assert_eq!(f.check(), Ok(()));
    }

    #[test]
    fn glued_sides_must_meet_and_poles_must_be_points() {
        let mut s = source(["cos(u)", "sin(u)", "v", "0"], [0.0, 6.0], [0.0, 1.0]);
        s.sides.u = Some(FormulaSeam::Periodic);
        let e = check_error(s);
        assert_eq!(e.field, "sides.u");
        assert!(
            e.message
                .starts_with("the side's points do not meet: (u, v) = (0, 0) is 2.822e-1 away"),
            "{e}"
        );
        assert!(
            e.message
                .contains("from the point it is glued to, (u, v) = (6, 0)"),
            "{e}"
        );
        let mut s = source(["cos(u)", "sin(u)", "v", "0"], [0.0, TAU], [0.0, 1.0]);
        s.sides.v_min = Some(FormulaEdge::Pole);
        let e = check_error(s);
        assert_eq!(e.field, "sides.v_min");
        assert!(
            e.message
                .contains("away from the pole's first point, (u, v) = (0, 0)"),
            "{e}"
        );
        let mut s = source(["cos(u)", "sin(u)", "v", "0"], [0.0, TAU], [0.0, 1.0]);
        s.sides.u = Some(FormulaSeam::Flip);
        assert_eq!(check_error(s).field, "sides.u");
        let mut s = source(["cos(u)", "sin(u)", "v", "0"], [0.0, TAU], [0.0, 1.0]);
        s.sides.v_max = Some(FormulaEdge::HalfTurn);
        assert_eq!(check_error(s).field, "sides.v_max");
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

    #[test]
    fn points_are_the_values_of_the_jets() {
        let f = Formula::example();
        for i in 0..50 {
            let (u, v) = (i as f64 * 0.13, i as f64 * 0.29);
            assert_eq!(f.point(0, u, v), f.eval(0, u, v).p);
        }
    }

    #[test]
    fn edit_distance_counts_edits() {
        assert_eq!(edit_distance("sine", "sin"), 1);
        assert_eq!(edit_distance("alpha", "alfa"), 2);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("kitten", "sitting"), 3);
    }
}
