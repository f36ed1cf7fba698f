//! A build's meshes held to the certified double curves ([`crate::intersect::certified`]):
//! where the meshes' curves count otherwise than the true surfaces' (a loop smaller than the
//! triangles missed, say), the surfaces sampled adaptively are sampled again, finer around
//! the certified curves only, a quarter of the tolerance more each round, until the counts
//! agree or [`ROUNDS`] rounds have passed. What still differs is the build's failure
//! (`CurvesReport::failures`), naming where.

use super::built::{InView, project_one};
use super::ms;
use super::report::Timings;
use super::sampled::sample_surface;
use crate::error::Error;
use crate::intersect::certified::{Certificate, SheetBox};
use crate::intersect::{self, Curves, Sheet};
use crate::progress::Task;
use crate::sample::Finer;
use crate::scene::Scene;
use std::time::Instant;

/// The most rounds of sampling again: the tolerance around the curves goes down to 4^-12 of
/// the surface's (about 6e-8).
pub(super) const ROUNDS: usize = 12;

/// The curves of `projections`' meshes, with the surfaces sampled again (and projected) as
/// the module says until their counts are the certificate's; and the rounds it took.
pub(super) fn hold<'a>(
    scene: &'a Scene,
    certificate: &Certificate,
    projections: &mut [InView<'a>],
    timings: &mut Timings,
    task: &Task,
) -> Result<(Curves, usize), Error> {
    let mut finer: Vec<Vec<Finer>> = vec![Vec::new(); projections.len()];
    let mut round = 0;
    loop {
        task.doing("intersection curves");
        let start = Instant::now();
        let curves = intersect::curves_until(&sheets(projections), task.job().cancel());
        task.job().check()?;
        timings.curves += ms(start);
        let agree =
            (curves.report.closed, curves.report.open) == (certificate.closed, certificate.open);
        if agree || !certificate.complete || round == ROUNDS {
            return Ok((curves, round));
        }
        // Each adaptive surface's tolerance this round, and the boxes of the certified
        // curves on it.
        let aims: Vec<Option<f64>> = projections
            .iter()
            .map(|p| {
                let t = p.sample.report.tolerance?;
                Some(t * 0.25f64.powi(round as i32 + 1))
            })
            .collect();
        // Each round's rectangles replace the last's: its tolerance is finer everywhere.
        finer.iter_mut().for_each(Vec::clear);
        let mut more = false;
        for component in &certificate.components {
            for b in component.boxes.iter().flatten() {
                if let Some(Some(tolerance)) = aims.get(b.surface) {
                    finer[b.surface].push(around(b, *tolerance));
                    more = true;
                }
            }
        }
        if !more {
            return Ok((curves, round));
        }
        task.doing(&format!(
            "sampling finer around the certified curves (round {})",
            round + 1
        ));
        for (i, view) in projections.iter_mut().enumerate() {
            if finer[i].is_empty() {
                continue;
            }
            let sample = sample_surface(scene, i, &finer[i], timings, task)?;
            *view = project_one(scene, view.entry, sample, timings, task)?;
        }
        round += 1;
    }
}

/// The rectangle a certified curve's box asks to be sampled finer: the box, twice as wide
/// about its middle (its face coordinate, which the box holds fixed, widened as the other),
/// so that the triangles on both sides of the curve, and inside a small loop, are held.
fn around(b: &SheetBox, tolerance: f64) -> Finer {
    let half = (b.u[1] - b.u[0]).max(b.v[1] - b.v[0]);
    let widen = |r: [f64; 2]| {
        let mid = 0.5 * (r[0] + r[1]);
        [mid - half, mid + half]
    };
    Finer {
        patch: b.patch,
        u: widen(b.u),
        v: widen(b.v),
        tolerance,
    }
}

/// The projected meshes as the curves take them.
fn sheets<'a>(projections: &'a [InView<'_>]) -> Vec<Sheet<'a>> {
    projections
        .iter()
        .map(|p| Sheet {
            positions: &p.projected.positions,
            w: &p.projected.w,
            triangles: &p.sample.mesh.triangles,
        })
        .collect()
}
