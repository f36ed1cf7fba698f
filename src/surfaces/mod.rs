//! The catalogue of 4D parametric surfaces.
//!
//! Takes: a surface entry of a scene (its type and parameters).
//! Gives: points of R^4 with exact first and second derivatives ([`Eval4`]) over one or more
//! rectangular parameter patches, and the [`Domain`] topology of each patch: which sides are
//! open, which collapse to a pole, and which are glued to which (periodic, with a flip, or to
//! another patch). The samplers weld meshes with these rules, never by distance.
//!
//! Guarantees: points are finite everywhere on the domain. Derivatives are exact (dual-number
//! [`Jet`]s, or closed forms for the holomorphic surfaces), never finite differences; they are
//! finite everywhere except at the isolated branch points of the Fermat parametrization, where
//! the parametrization (not the surface) is singular.

mod formula;
mod holomorphic;
mod interval;
mod jet;
mod knots;
mod simple;

pub use formula::{Bound, Formula, FormulaEdge, FormulaSeam, FormulaSides, FormulaSource};
pub use holomorphic::{Fermat, ProductPolynomial};
pub use interval::Interval;
pub use jet::{Jet, Real, Scalar};
pub use knots::{SpunTrefoil, TwistSpunTrefoil};
pub use simple::{FlatTorus, KleinBottle, Patches, ProjectivePlane};

use crate::limits::FieldError;
use glam::DVec4;
use serde::{Deserialize, Serialize};

/// A surface point with its exact first and second partial derivatives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Eval4 {
    /// The point.
    pub p: DVec4,
    /// ∂p/∂u.
    pub du: DVec4,
    /// ∂p/∂v.
    pub dv: DVec4,
    /// ∂²p/∂u².
    pub duu: DVec4,
    /// ∂²p/∂u∂v.
    pub duv: DVec4,
    /// ∂²p/∂v².
    pub dvv: DVec4,
}

impl Eval4 {
    /// Collects four coordinate jets into points and derivative vectors.
    pub fn from_jets(c: [Jet; 4]) -> Self {
        let pick = |f: fn(&Jet) -> f64| DVec4::new(f(&c[0]), f(&c[1]), f(&c[2]), f(&c[3]));
        Eval4 {
            p: pick(|j| j.v),
            du: pick(|j| j.du),
            dv: pick(|j| j.dv),
            duu: pick(|j| j.duu),
            duv: pick(|j| j.duv),
            dvv: pick(|j| j.dvv),
        }
    }

    /// Whether the two tangents are finite (they are not at parametrization singularities).
    pub fn tangents_finite(&self) -> bool {
        self.du.is_finite() && self.dv.is_finite()
    }
}

/// A side of a patch's parameter rectangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
pub enum Side {
    /// u = u_min; the side coordinate runs with v.
    U0,
    /// u = u_max; the side coordinate runs with v.
    U1,
    /// v = v_min; the side coordinate runs with u.
    V0,
    /// v = v_max; the side coordinate runs with u.
    V1,
}

impl Side {
    /// All four sides, in the order used by [`Domain::sides`].
    pub const ALL: [Side; 4] = [Side::U0, Side::U1, Side::V0, Side::V1];

    fn index(self) -> usize {
        self as usize
    }
}

/// One piece of a glued side: the part `sigma` in `[from, to]` of the side (normalized side
/// coordinate, 0 at the low parameter end, 1 at the high end) is identified with the side
/// `side` of patch `patch`, at `offset + sigma` (or `offset - sigma` when `reversed`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Glue {
    /// Start of the piece on this side.
    pub from: f64,
    /// End of the piece on this side.
    pub to: f64,
    /// The patch this piece is glued to (may be the same patch).
    pub patch: usize,
    /// The side of that patch.
    pub side: Side,
    /// Offset of the affine map of side coordinates.
    pub offset: f64,
    /// Whether the side coordinate runs backwards on the other side.
    pub reversed: bool,
}

impl Glue {
    /// The whole side glued to `side` of `patch`, straight (periodic) or with a flip.
    pub fn whole(patch: usize, side: Side, reversed: bool) -> Self {
        Glue {
            from: 0.0,
            to: 1.0,
            patch,
            side,
            offset: if reversed { 1.0 } else { 0.0 },
            reversed,
        }
    }

    /// The side coordinate on the other side for `sigma` on this one.
    pub fn map(&self, sigma: f64) -> f64 {
        if self.reversed {
            self.offset - sigma
        } else {
            self.offset + sigma
        }
    }
}

/// What happens at one side of a patch.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub enum SideRule {
    /// An open boundary of the surface.
    Open,
    /// The whole side is one point of the surface (a pole).
    Pole,
    /// The side is glued, piece by piece, to sides of this or other patches.
    Glued(Vec<Glue>),
}

/// The parameter rectangle of a patch and the rule of each of its sides.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Domain {
    /// Range of u.
    pub u: [f64; 2],
    /// Range of v.
    pub v: [f64; 2],
    /// Rules for the sides, in the order of [`Side::ALL`].
    pub sides: [SideRule; 4],
}

impl Domain {
    /// A rectangle with all four sides open.
    pub fn open(u: [f64; 2], v: [f64; 2]) -> Self {
        Domain {
            u,
            v,
            sides: [
                SideRule::Open,
                SideRule::Open,
                SideRule::Open,
                SideRule::Open,
            ],
        }
    }

    /// The rule of one side.
    pub fn side(&self, side: Side) -> &SideRule {
        &self.sides[side.index()]
    }

    /// Sets the rule of one side.
    pub fn with(mut self, side: Side, rule: SideRule) -> Self {
        self.sides[side.index()] = rule;
        self
    }

    /// Makes u periodic (patch `patch` glued to itself across the u sides), optionally with
    /// a flip of v (Klein bottle).
    pub fn glue_u(self, patch: usize, flip: bool) -> Self {
        self.with(
            Side::U0,
            SideRule::Glued(vec![Glue::whole(patch, Side::U1, flip)]),
        )
        .with(
            Side::U1,
            SideRule::Glued(vec![Glue::whole(patch, Side::U0, flip)]),
        )
    }

    /// Makes v periodic.
    pub fn glue_v(self, patch: usize) -> Self {
        self.with(
            Side::V0,
            SideRule::Glued(vec![Glue::whole(patch, Side::V1, false)]),
        )
        .with(
            Side::V1,
            SideRule::Glued(vec![Glue::whole(patch, Side::V0, false)]),
        )
    }

    /// The parameters of the point at side coordinate `sigma` of `side`.
    pub fn side_point(&self, side: Side, sigma: f64) -> (f64, f64) {
        let lerp = |r: [f64; 2], t: f64| r[0] + (r[1] - r[0]) * t;
        match side {
            Side::U0 => (self.u[0], lerp(self.v, sigma)),
            Side::U1 => (self.u[1], lerp(self.v, sigma)),
            Side::V0 => (lerp(self.u, sigma), self.v[0]),
            Side::V1 => (lerp(self.u, sigma), self.v[1]),
        }
    }
}

/// Global topology of a surface, for checks on its meshes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Topology {
    /// Whether the surface is closed (no boundary).
    pub closed: bool,
    /// Whether the surface is orientable.
    pub orientable: bool,
    /// The Euler characteristic (of the surface with its boundary, where it has one).
    pub euler_characteristic: Option<i64>,
}

/// A surface of the catalogue with its parameters, as written in a scene file
/// (`{"type": "spun_trefoil", "scale": 0.5}`), or the user's own [`Formula`]. Every
/// parameter of a catalogue entry has a default.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Surface {
    /// Flat (Clifford) torus.
    FlatTorus(FlatTorus),
    /// Klein bottle embedded in R^4.
    KleinBottle(KleinBottle),
    /// Real projective plane embedded in R^4 (Veronese-type map).
    ProjectivePlane(ProjectivePlane),
    /// Artin spin of a knotted trefoil arc: a knotted 2-sphere.
    SpunTrefoil(SpunTrefoil),
    /// Zeeman twist spin of the trefoil arc with m >= 2 twists: a knotted 2-sphere.
    TwistSpunTrefoil(TwistSpunTrefoil),
    /// Fermat surface z1^n + z2^n = 1 (n^2 patches).
    Fermat(Fermat),
    /// Product polynomial z1^2 z2^2 = 1.
    ProductPolynomial(ProductPolynomial),
    /// The test scene of paper 000 fig. 1: planar patches at different w crossing a white one.
    Patches(Patches),
    /// The user's own surface: four formulas in (u, v) with side rules.
    Formula(Formula),
}

/// Reads `{"type": ..., params}` in two steps so that an error in a parameter names it
/// (serde's internally tagged enums lose the field's path).
impl<'de> Deserialize<'de> for Surface {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        let mut map = serde_json::Map::deserialize(d)?;
        let ty = match map.remove("type") {
            Some(serde_json::Value::String(t)) => t,
            Some(other) => {
                return Err(D::Error::custom(format!(
                    "`type` must be a string, got {other}"
                )));
            }
            None => return Err(D::Error::missing_field("type")),
        };
        let params = serde_json::Value::Object(map);
        fn read<T: serde::de::DeserializeOwned, E: Error>(v: serde_json::Value) -> Result<T, E> {
            serde_path_to_error::deserialize(v).map_err(|e| match e.path().to_string().as_str() {
                "." => E::custom(e.inner()),
                path => E::custom(FieldError::new(path, e.inner().to_string())),
            })
        }
        Ok(match ty.as_str() {
            "flat_torus" => Surface::FlatTorus(read(params)?),
            "klein_bottle" => Surface::KleinBottle(read(params)?),
            "projective_plane" => Surface::ProjectivePlane(read(params)?),
            "spun_trefoil" => Surface::SpunTrefoil(read(params)?),
            "twist_spun_trefoil" => Surface::TwistSpunTrefoil(read(params)?),
            "fermat" => Surface::Fermat(read(params)?),
            "product_polynomial" => Surface::ProductPolynomial(read(params)?),
            "patches" => Surface::Patches(read(params)?),
            // Parsed in two steps too: a formula's error names its own field (`x: cannot
            // read the formula ...`, which the scene joins to its path) with a caret.
            "formula" => {
                let source: FormulaSource = read(params)?;
                Surface::Formula(Formula::new(source).map_err(D::Error::custom)?)
            }
            _ => {
                let mut known: Vec<&str> = Surface::catalogue()
                    .iter()
                    .map(Surface::type_name)
                    .collect();
                known.push("formula");
                // A scene's surface may also be a mesh file (`sample::Source` reads that
                // type before it asks the catalogue).
                known.push("mesh");
                return Err(D::Error::custom(format!(
                    "unknown surface type `{ty}`, expected one of {}",
                    known.join(", ")
                )));
            }
        })
    }
}

/// What every catalogue entry provides.
pub(crate) trait Parametric {
    fn patch_count(&self) -> usize;
    fn domain(&self, patch: usize) -> Domain;
    fn eval(&self, patch: usize, u: f64, v: f64) -> Eval4;
    /// Enclosures of the point and of its derivatives over the box `u` x `v` of a patch:
    /// what the surface takes at every point of the box lies in them.
    fn enclose(&self, patch: usize, u: Interval, v: Interval) -> [Jet<Interval>; 4];
    /// The point alone (the samplers' and the audit's hot path); surfaces with a cheaper
    /// way than [`Parametric::eval`] override it.
    fn point(&self, patch: usize, u: f64, v: f64) -> DVec4 {
        self.eval(patch, u, v).p
    }
    fn topology(&self) -> Topology;
    /// Checks parameter values, naming the first bad one.
    fn check(&self) -> Result<(), FieldError>;
    /// The fewest grid cells along (u, v) that give a simplicial mesh: 4 across a seam or
    /// a pole, more where a side is glued to itself.
    fn min_cells(&self) -> [usize; 2] {
        [4, 4]
    }
}

macro_rules! dispatch {
    ($self:expr, $s:ident => $e:expr) => {
        match $self {
            Surface::FlatTorus($s) => $e,
            Surface::KleinBottle($s) => $e,
            Surface::ProjectivePlane($s) => $e,
            Surface::SpunTrefoil($s) => $e,
            Surface::TwistSpunTrefoil($s) => $e,
            Surface::Fermat($s) => $e,
            Surface::ProductPolynomial($s) => $e,
            Surface::Patches($s) => $e,
            Surface::Formula($s) => $e,
        }
    };
}

impl Surface {
    /// One default-parametrized instance of every catalogue entry (a [`Formula`] has no
    /// default: see [`Formula::example`]).
    pub fn catalogue() -> Vec<Surface> {
        vec![
            Surface::FlatTorus(FlatTorus::default()),
            Surface::KleinBottle(KleinBottle::default()),
            Surface::ProjectivePlane(ProjectivePlane::default()),
            Surface::SpunTrefoil(SpunTrefoil::default()),
            Surface::TwistSpunTrefoil(TwistSpunTrefoil::default()),
            Surface::Fermat(Fermat::default()),
            Surface::ProductPolynomial(ProductPolynomial::default()),
            Surface::Patches(Patches::default()),
        ]
    }

    /// The catalogue as `halo4d list` prints it: each surface's type and description, its
    /// patches and its parameters' defaults.
    pub fn catalogue_listing() -> String {
        let mut out = String::new();
        for s in Surface::catalogue() {
            let mut params = serde_json::to_value(&s).unwrap_or_default();
            if let Some(map) = params.as_object_mut() {
                map.remove("type");
            }
            out += &format!("{:<20} {}\n", s.type_name(), s.description());
            out += &format!(
                "{:<20} patches: {}, defaults: {}\n",
                "",
                s.patch_count(),
                params
            );
        }
        let example = Surface::Formula(Formula::example());
        out += &format!("{:<20} {}\n", example.type_name(), example.description());
        // A whole scene, which builds as it is when saved as a file.
        let scene = serde_json::json!({
            "name": "my-formula",
            "surfaces": [{ "surface": serde_json::to_value(&example).unwrap_or_default() }],
        });
        out += &format!("{:<20} a scene: {scene}\n", "");
        out
    }

    /// The `type` name used in scene files.
    pub fn type_name(&self) -> &'static str {
        match self {
            Surface::FlatTorus(_) => "flat_torus",
            Surface::KleinBottle(_) => "klein_bottle",
            Surface::ProjectivePlane(_) => "projective_plane",
            Surface::SpunTrefoil(_) => "spun_trefoil",
            Surface::TwistSpunTrefoil(_) => "twist_spun_trefoil",
            Surface::Fermat(_) => "fermat",
            Surface::ProductPolynomial(_) => "product_polynomial",
            Surface::Patches(_) => "patches",
            Surface::Formula(_) => "formula",
        }
    }

    /// A one-line description for `halo4d list`.
    pub fn description(&self) -> &'static str {
        match self {
            Surface::FlatTorus(_) => {
                "flat (Clifford) torus (r1 cos s, r1 sin s, r2 cos t, r2 sin t)"
            }
            Surface::KleinBottle(_) => "Klein bottle embedded in R^4",
            Surface::ProjectivePlane(_) => "real projective plane, Veronese-type embedding in R^4",
            Surface::SpunTrefoil(_) => "Artin-spun trefoil: a knotted 2-sphere",
            Surface::TwistSpunTrefoil(_) => {
                "Zeeman twist-spun trefoil (m >= 2): a knotted 2-sphere"
            }
            Surface::Fermat(_) => {
                "Fermat surface z1^n + z2^n = 1 (n^2 patches; n = 4: Calabi-Yau quartic section)"
            }
            Surface::ProductPolynomial(_) => "product polynomial z1^2 z2^2 = 1 (two sheets)",
            Surface::Patches(_) => {
                "paper 000 fig. 1: planar patches at different w crossing a white one"
            }
            Surface::Formula(_) => {
                "your own surface: formulas x, y, z, w in u, v, pi, e and `parameters` (+ - * / ^, sin cos tan asin acos atan atan2 sinh cosh tanh exp log sqrt abs min max), ranges `u`, `v` and `sides` (u, v: open, periodic, flip; u_min, u_max, v_min, v_max: open, pole, half_turn)"
            }
        }
    }

    /// Number of parameter patches.
    pub fn patch_count(&self) -> usize {
        dispatch!(self, s => s.patch_count())
    }

    /// The domain and side rules of a patch.
    pub fn domain(&self, patch: usize) -> Domain {
        dispatch!(self, s => s.domain(patch))
    }

    /// The point and its exact derivatives at (u, v) of a patch.
    pub fn eval(&self, patch: usize, u: f64, v: f64) -> Eval4 {
        dispatch!(self, s => s.eval(patch, u, v))
    }

    /// Enclosures of the point and of its first and second derivatives over the box of
    /// parameters `u` x `v` of a patch, by interval arithmetic rounded outward: every
    /// value the surface and its derivatives take on the box lies in them. Where the
    /// surface has a kink or its parametrization a singularity inside the box, the
    /// derivatives' enclosures are unbounded.
    pub fn enclose(&self, patch: usize, u: Interval, v: Interval) -> [Jet<Interval>; 4] {
        dispatch!(self, s => s.enclose(patch, u, v))
    }

    /// The point at (u, v) of a patch, without derivatives: the same as `eval(..).p`, faster
    /// for some surfaces.
    pub fn point(&self, patch: usize, u: f64, v: f64) -> DVec4 {
        dispatch!(self, s => s.point(patch, u, v))
    }

    /// Closedness, orientability and Euler characteristic.
    pub fn topology(&self) -> Topology {
        dispatch!(self, s => s.topology())
    }

    /// The fewest uniform grid cells along (u, v) that give a simplicial mesh.
    pub fn min_cells(&self) -> [usize; 2] {
        dispatch!(self, s => s.min_cells())
    }

    /// The parameters of the point that `(u, v)` of `patch` reaches when they may lie past
    /// the patch's rectangle (a step of Newton's method near a seam): past a glued side, the
    /// point as far inside the side it is glued to, in shares of each rectangle's extent
    /// across the side (again for a corner). The flag says whether the result lies in its
    /// patch's rectangle: past an open side or a pole the parameters are returned as they
    /// are, with `false`. Overshoots below 1e-12 of the extent are rounding and count as in.
    pub fn chart(&self, mut patch: usize, mut u: f64, mut v: f64) -> (usize, f64, f64, bool) {
        const SLACK: f64 = 1e-12;
        for _ in 0..4 {
            let d = self.domain(patch);
            let (eu, ev) = (d.u[1] - d.u[0], d.v[1] - d.v[0]);
            let (su, sv) = ((u - d.u[0]) / eu, (v - d.v[0]) / ev);
            let over = [-su, su - 1.0, -sv, sv - 1.0];
            let (k, depth) =
                over.iter()
                    .copied()
                    .enumerate()
                    .fold(
                        (0, f64::NEG_INFINITY),
                        |m, (k, o)| if o > m.1 { (k, o) } else { m },
                    );
            if depth.partial_cmp(&SLACK) != Some(std::cmp::Ordering::Greater) {
                return (patch, u, v, depth.is_finite());
            }
            // The piece is chosen at the side; past a corner the other coordinate carries
            // its own overshoot across, for the next round.
            let sigma = if k < 2 { sv } else { su };
            let at = sigma.clamp(0.0, 1.0);
            let SideRule::Glued(pieces) = d.side(Side::ALL[k]) else {
                return (patch, u, v, false);
            };
            let Some(g) = pieces.iter().find(|g| g.from <= at && at <= g.to) else {
                return (patch, u, v, false);
            };
            let to = self.domain(g.patch);
            let (u2, v2) = to.side_point(g.side, g.map(sigma));
            let (eu2, ev2) = (to.u[1] - to.u[0], to.v[1] - to.v[0]);
            (u, v) = match g.side {
                Side::U0 => (u2 + depth * eu2, v2),
                Side::U1 => (u2 - depth * eu2, v2),
                Side::V0 => (u2, v2 + depth * ev2),
                Side::V1 => (u2, v2 - depth * ev2),
            };
            patch = g.patch;
        }
        (patch, u, v, false)
    }

    /// Checks the parameters: names the first bad field. A catalogue surface's size
    /// parameters must also keep it within [`crate::limits::MAX_COORDINATE`] (a formula's
    /// own check walks a grid of its own).
    pub fn check(&self) -> Result<(), FieldError> {
        dispatch!(self, s => s.check())?;
        if matches!(self, Surface::Formula(_)) {
            return Ok(());
        }
        self.check_extent()
    }

    /// The surface measured on a coarse grid of every patch before anything is sampled: a
    /// point beyond [`crate::limits::MAX_COORDINATE`], or not finite, is refused at once, so
    /// that a size of 1e308 does not sample for half a minute to fail in the view.
    fn check_extent(&self) -> Result<(), FieldError> {
        const STEPS: usize = 8;
        for patch in 0..self.patch_count() {
            let d = self.domain(patch);
            for i in 0..=STEPS {
                for j in 0..=STEPS {
                    let t = |r: [f64; 2], k: usize| r[0] + (r[1] - r[0]) * k as f64 / STEPS as f64;
                    let (u, v) = (t(d.u, i), t(d.v, j));
                    let largest = self.point(patch, u, v).abs().max_element();
                    if largest.is_nan() || largest > crate::limits::MAX_COORDINATE {
                        // The parameter that scales the surface.
                        let size = match self {
                            Surface::FlatTorus(_) => "r1",
                            Surface::KleinBottle(_) => "major_radius",
                            Surface::ProjectivePlane(_) => "radius",
                            Surface::SpunTrefoil(_) | Surface::TwistSpunTrefoil(_) => "scale",
                            Surface::Fermat(_) => "y_range",
                            Surface::ProductPolynomial(_) => "u_range",
                            Surface::Patches(_) => "size",
                            Surface::Formula(_) => "x",
                        };
                        return Err(FieldError::new(
                            size,
                            format!(
                                "reaches a coordinate of {largest:.3e} (patch {patch}, u = {u:.3}, v = {v:.3}), beyond {:e}, where the files' f32 and the exact predicates stay exact; make it smaller",
                                crate::limits::MAX_COORDINATE
                            ),
                        ));
                    }
                }
            }
        }
        Ok(())
    }
}
