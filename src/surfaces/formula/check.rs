//! The scene's check of a formula surface: [`Formula`] evaluated on a grid of its domain,
//! its points, derivatives and bends judged, and its glued sides and poles compared. Apart
//! from the compiler: a formula that compiles can still be infinite, not differentiable or
//! too sharp somewhere in its ranges, which only running it tells.

use super::{COMPONENTS, Formula};
use crate::limits::{FORMULA_BEND, FORMULA_GLUE, FieldError, MAX_COORDINATE};
use crate::surfaces::{Jet, Parametric, Side, SideRule};
use glam::DVec4;

impl Formula {
    /// The points of the check grid with their jets: a regular grid with the sides, then
    /// the same grid shifted inside its cells by irrational shares, so that a frequency
    /// that fits the regular grid (sin(1e5 u) over [0, 2π] is 0 at all its points) does
    /// not hide from the check.
    pub(super) fn check_grid(&self) -> Vec<(f64, f64, [Jet; 4])> {
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
    pub(super) fn check_points(&self, grid: &[(f64, f64, [Jet; 4])]) -> Result<(), FieldError> {
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
    pub(super) fn check_derivatives(
        &self,
        grid: &[(f64, f64, [Jet; 4])],
    ) -> Result<(), FieldError> {
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
    pub(super) fn diagonal(grid: &[(f64, f64, [Jet; 4])]) -> f64 {
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
    pub(super) fn check_bend(
        &self,
        grid: &[(f64, f64, [Jet; 4])],
        diagonal: f64,
    ) -> Result<(), FieldError> {
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
    pub(super) fn check_sides(&self, diagonal: f64) -> Result<(), FieldError> {
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

#[cfg(test)]
mod tests {
    use super::super::tests::{check_error, formula, source};
    use super::super::{FormulaEdge, FormulaSeam};
    use crate::surfaces::Parametric;
    use std::f64::consts::{FRAC_PI_2, PI, TAU};

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
}
