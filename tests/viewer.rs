//! The wgpu viewer, headless (on a software Vulkan driver in CI): every fixture against the
//! CPU renderer's exact mode, both slicing modes, and files it must refuse.

use crate::common::fixture_scenes;
use halo4d::Scene;
use halo4d::render::compare::verdict_differs;
use halo4d::render::{RenderMode, RenderSettings, render_with_depth};
use halo4d::viewer::{self, Asset, Gpu, HaloMode, ViewSettings, ViewerError};
use std::path::Path;
use std::sync::OnceLock;

/// The GPU (created once): a missing adapter fails the tests, it does not skip them.
fn gpu() -> &'static Gpu {
    static GPU: OnceLock<Gpu> = OnceLock::new();
    GPU.get_or_init(|| {
        let gpu = Gpu::headless().unwrap_or_else(|e| panic!("{e}"));
        eprintln!("viewer tests on {}", gpu.describe());
        gpu
    })
}

/// GPU and CPU distances agree to this relative tolerance (the GPU works in f32).
const SAME: f64 = 1e-4;
const SIDE: u32 = 320;

/// Builds `scene` into `dir` and loads its `.glb` as the viewer does.
fn exported(scene: &Scene, dir: &Path) -> (halo4d::Built, Asset) {
    let built = halo4d::run(scene, true).unwrap();
    halo4d::write(scene, &built, dir).unwrap();
    let glb = dir.join(format!("{}.glb", scene.name));
    let asset = Asset::load(&glb).unwrap_or_else(|e| panic!("{e}"));
    (built, asset)
}

/// The CPU renderer's exact mode at `SIDE`, one sample per pixel (at its centre, where the
/// GPU rasterizes): per pixel, the distance to the first visible surface.
fn exact_distances(scene: &Scene, built: &halo4d::Built) -> Vec<f64> {
    let settings = RenderSettings {
        width: SIDE,
        height: SIDE,
        samples: 1,
        mode: RenderMode::Exact,
        ..scene.render
    };
    let parts = built.render_parts(&scene.halo);
    render_with_depth(&parts.input(), &settings, &scene.camera)
        .unwrap()
        .1
}

fn settings(scene: &Scene, mode: HaloMode, slices: u32) -> ViewSettings {
    ViewSettings {
        width: SIDE,
        height: SIDE,
        camera: scene.camera,
        slices,
        mode,
        ..ViewSettings::default()
    }
}

fn distances(frame: &viewer::Frame) -> Vec<f64> {
    frame.distance.iter().map(|&d| f64::from(d)).collect()
}

#[test]
fn every_fixture_matches_the_exact_cpu_render_at_256_slices() {
    let gpu = gpu();
    let mut worst = (0.0f64, String::new());
    for path in fixture_scenes() {
        let scene = Scene::load(&path).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let (built, asset) = exported(&scene, dir.path());
        assert!(
            asset.surfaces_without_halo.is_empty(),
            "{}: every fixture has halos",
            scene.name
        );
        let exact = exact_distances(&scene, &built);
        // What the halos hide at all: the verdict without them. A viewer whose halos hid
        // nothing would be this far off.
        let off = ViewSettings {
            halos: false,
            ..settings(&scene, HaloMode::Grid, 256)
        };
        let hidden = verdict_differs(
            &exact,
            &distances(&viewer::screenshot(gpu, &asset, &off).unwrap()),
            SAME,
        );
        let mut line = format!("{:<26} halos off: {:.3}%", scene.name, hidden * 100.0);
        for mode in [HaloMode::Grid, HaloMode::View] {
            let frame = viewer::screenshot(gpu, &asset, &settings(&scene, mode, 256))
                .unwrap_or_else(|e| panic!("{}: {e}", scene.name));
            assert_eq!(frame.picture.rgb.len(), (3 * SIDE * SIDE) as usize);
            let differs = verdict_differs(&exact, &distances(&frame), SAME);
            line.push_str(&format!(" {}: {:.3}%", mode.name(), differs * 100.0));
            assert!(
                differs < 0.02,
                "{} ({} mode): the verdict differs on {:.2}% of covered pixels",
                scene.name,
                mode.name(),
                differs * 100.0
            );
            // Where halos hide a visible share, the viewer gets most of it right.
            assert!(
                hidden < 0.005 || differs < hidden / 4.0,
                "{} ({} mode): {:.2}% differ, against {:.2}% with no halos at all",
                scene.name,
                mode.name(),
                differs * 100.0,
                hidden * 100.0
            );
            if differs > worst.0 {
                worst = (differs, format!("{} ({})", scene.name, mode.name()));
            }
        }
        eprintln!("{line}");
    }
    eprintln!(
        "largest verdict difference: {:.3}% ({})",
        worst.0 * 100.0,
        worst.1
    );
}
