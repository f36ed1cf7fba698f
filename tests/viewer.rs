//! The wgpu viewer, headless (on a software Vulkan driver in CI): every fixture against the
//! CPU renderer's exact mode, both slicing modes, and files it must refuse.

use crate::common::{Rng, fixture_scenes};
use halo4d::Scene;
use halo4d::internals::verdict_differs;
use halo4d::render::render_with_depth;
use halo4d::view::Rotation4;
use halo4d::viewer::{self, Asset, Gpu, HaloMode, Model, ViewSettings};
use halo4d::{render::RenderMode, render::RenderSettings};
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
    let built = crate::common::built(scene).unwrap();
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
    let parts = built.parts(&scene.halo);
    render_with_depth(&parts, &settings, &scene.camera)
        .unwrap()
        .1
}

fn settings(scene: &Scene, mode: HaloMode, slices: u32) -> ViewSettings {
    ViewSettings {
        render: RenderSettings {
            width: SIDE,
            height: SIDE,
            slices,
            ..ViewSettings::default().render
        },
        camera: scene.camera,
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
            render: RenderSettings {
                halos: false,
                ..settings(&scene, HaloMode::Grid, 256).render
            },
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
            // Where halos hide a visible share, the viewer gets most of it right: the
            // tightest is the spun trefoil in perspective in view mode, 0.26% against 0.96%
            // (every other fixture below a tenth).
            assert!(
                hidden < 0.005 || differs < hidden / 3.0,
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

#[test]
fn a_cutaway_removes_on_the_gpu_what_the_cpu_renderer_removes() {
    // The Klein bottle keeps its double curves inside: a wedge through its centre opens it.
    let gpu = gpu();
    let mut scene = Scene::load(&crate::common::fixture("scenes/klein-bottle.json")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let (_, asset) = exported(&scene, dir.path());
    let c = asset.centre();
    scene.render.clip = Some(halo4d::render::Clip::wedge(
        halo4d::render::ClipPlane {
            normal: [0.0, 0.0, 1.0],
            offset: c.z,
        },
        halo4d::render::ClipPlane {
            normal: [1.0, 0.0, 0.0],
            offset: c.x,
        },
    ));
    let built = crate::common::built(&scene).unwrap();
    let exact = exact_distances(&scene, &built);
    let whole = distances(
        &viewer::screenshot(gpu, &asset, &settings(&scene, HaloMode::Grid, 256)).unwrap(),
    );
    let removed = verdict_differs(&exact, &whole, SAME);
    for mode in [HaloMode::Grid, HaloMode::View] {
        let cut = ViewSettings {
            render: RenderSettings {
                clip: scene.render.clip,
                ..settings(&scene, mode, 256).render
            },
            ..settings(&scene, mode, 256)
        };
        let frame = viewer::screenshot(gpu, &asset, &cut).unwrap();
        let differs = verdict_differs(&exact, &distances(&frame), SAME);
        eprintln!(
            "klein-bottle cut ({}): {:.3}% differ from the CPU, {:.1}% without the cut",
            mode.name(),
            differs * 100.0,
            removed * 100.0
        );
        assert!(
            differs < 0.02,
            "{}: {:.2}% differ",
            mode.name(),
            differs * 100.0
        );
    }
    assert!(
        removed > 0.1,
        "the cut changes {:.1}% of the picture",
        removed * 100.0
    );
    // The cut edges in the ink (no other line drawn): none without the cut.
    let ink = |clip| {
        let s = ViewSettings {
            render: RenderSettings {
                clip,
                curves: false,
                silhouettes: false,
                ..settings(&scene, HaloMode::Grid, 256).render
            },
            ..settings(&scene, HaloMode::Grid, 256)
        };
        let frame = viewer::screenshot(gpu, &asset, &s).unwrap();
        frame
            .picture
            .rgb
            .chunks(3)
            .filter(|c| c.iter().all(|&v| v < 45))
            .count()
    };
    let (cut, uncut) = (ink(scene.render.clip), ink(None));
    assert!(
        cut > 200 && uncut == 0,
        "ink pixels: {cut} cut, {uncut} uncut"
    );
}

#[test]
fn the_explorer_draws_the_curves_a_build_shows() {
    // The explorer samples through the library and asks it for the curves of each view: the
    // same refined curves as the build (they were the mesh's, up to 1e-2 away).
    for name in ["default", "klein-bottle", "fermat-quadratic"] {
        let scene = Scene::load(&crate::common::fixture(&format!("scenes/{name}.json"))).unwrap();
        assert!(scene.curves.refine, "{name} refines its curves");
        let built = crate::common::built(&scene).unwrap();
        let model = Model::new(scene.clone()).unwrap();
        let turned = |rotation: Rotation4| halo4d::view::View {
            rotation,
            ..scene.view
        };
        let shown = model.curves(&scene.view).unwrap();
        assert!(!shown.curves.is_empty(), "{name}");
        assert_eq!(shown.curves, built.shown_curves().curves, "{name}");
        assert_ne!(
            shown.curves, built.curves.curves,
            "{name}: the refined curves are not the mesh's"
        );
        // Another view: what a build in that view shows.
        let mut rotation = scene.view.rotation;
        rotation.xw += 7.0;
        let mut other = scene.clone();
        other.view = turned(rotation);
        let built = crate::common::built(&other).unwrap();
        assert_eq!(
            model.curves(&other.view).unwrap().curves,
            built.shown_curves().curves,
            "{name} turned"
        );
    }
}

#[test]
fn the_explorer_shows_the_slices_halo4d_slice_makes_over_the_surfaces() {
    let gpu = gpu();
    let scene = Scene::load(&crate::common::fixture("scenes/default.json")).unwrap();
    let model = Model::new(scene.clone()).unwrap();
    let mut plane = model.hyperplane(None).unwrap();
    // The hyperplane is `halo4d slice`'s: the same direction and critical levels, and at
    // each still's level as many curves.
    let dir = tempfile::tempdir().unwrap();
    let motion = halo4d::slicing::slice_scene(
        &scene,
        scene.slicing.unwrap(),
        dir.path(),
        halo4d::progress::Job::SILENT,
    )
    .unwrap();
    let surface = &motion.surfaces[0];
    // The scene's mesh changes its slices off the surface's critical levels: both cut the
    // surface sampled again through its critical points, and the explorer says so.
    let again = surface
        .resampled
        .expect("sampled again through its critical points");
    assert_eq!(
        plane.notes,
        [format!(
            "spun_trefoil sliced as sampled again at {:.3e} of its diagonal ({} triangles)",
            again.relative_tolerance, again.triangles
        )]
    );
    assert!((plane.direction - surface.direction).length() < 1e-15);
    let levels = |points: &[halo4d::motion::CriticalPoint]| -> Vec<(String, f64)> {
        points
            .iter()
            .map(|p| (p.event.name().to_string(), p.level))
            .collect()
    };
    assert_eq!(levels(&plane.critical), levels(&surface.critical_points));
    assert!(surface.stills.len() >= 5);
    for still in &surface.stills {
        plane.move_to(still.level);
        let curves: usize = plane.slices.iter().map(|s| s.curves.len()).sum();
        assert_eq!(curves, still.curves, "at level {}", still.level);
        assert!(plane.slices.iter().all(|s| s.max_residual <= 1e-12));
    }
    // It starts in the middle of the heights, here about c = 0, the square knot: one curve,
    // and the title says between which events it lies; it stays within the heights.
    let mut plane = model.hyperplane(None).unwrap();
    let (lo, hi) = plane.range;
    assert_eq!(plane.level, 0.5 * (lo + hi));
    assert!(plane.level.abs() < 1e-3 * (hi - lo), "{}", plane.level);
    let title = plane.describe();
    assert!(
        title.contains(": 1 curve |")
            && title.contains("below: saddle at -0.2907")
            && title.contains("above: saddle at 0.2907"),
        "{title}"
    );
    let middle = plane.level;
    plane.step(10.0);
    assert_eq!(plane.level, plane.range.1);
    assert!(
        plane
            .describe()
            .contains("0 curves | below: death at 1.6542"),
        "{}",
        plane.describe()
    );
    assert!(plane.describe().ends_with("above: nothing"));
    plane.move_to(middle);
    // Drawn: every pixel the slice changes lies on a projected slice curve, and there are
    // many, in the slice's magenta.
    let view = scene.view;
    let base = ViewSettings {
        render: RenderSettings {
            curves: false,
            silhouettes: false,
            ..settings(&scene, HaloMode::Grid, 256).render
        },
        ..settings(&scene, HaloMode::Grid, 256)
    };
    let mut renderer =
        viewer::Renderer::for_model(gpu, &model, &view, viewer::OFFSCREEN_FORMAT).unwrap();
    let without = renderer.read_frame(gpu, &base).unwrap();
    let polylines = plane.polylines(&view);
    assert_eq!(polylines.len(), 1);
    renderer.set_slice(gpu, &polylines).unwrap();
    let with = renderer.read_frame(gpu, &base).unwrap();
    let segments = pixel_segments(
        &scene.camera,
        renderer.asset(),
        polylines
            .iter()
            .map(|(points, closed)| (points.clone(), *closed)),
    );
    let (mut changed, mut magenta) = (0, 0);
    for (x, y, ink) in changed_pixels(&with, &without) {
        changed += 1;
        magenta += usize::from(ink[0] > 150 && ink[2] > 120 && ink[1] < 60);
        assert!(
            near(&segments, x, y, 2.25),
            "pixel ({x}, {y}) changed away from the slice"
        );
    }
    assert!(
        magenta > 100,
        "{magenta} of {changed} changed pixels magenta"
    );
    // A turn drops the slice until it is given for the new view.
    let mut turned = view;
    turned.rotation.xw += 20.0;
    renderer.turn(gpu, &model, &turned).unwrap();
    let bare = renderer.read_frame(gpu, &base).unwrap();
    renderer.set_slice(gpu, &plane.polylines(&turned)).unwrap();
    let again = renderer.read_frame(gpu, &base).unwrap();
    assert_ne!(bare.picture.rgb, again.picture.rgb);
    renderer.set_slice(gpu, &[]).unwrap();
    assert_eq!(
        renderer.read_frame(gpu, &base).unwrap().picture.rgb,
        bare.picture.rgb
    );
}

/// The segments of `lines` (points in the asset's frame, and whether each closes) in
/// pixels of a `SIDE` x `SIDE` frame through `camera`.
fn pixel_segments(
    camera: &halo4d::render::CameraSettings,
    asset: &Asset,
    lines: impl Iterator<Item = (Vec<glam::DVec3>, bool)>,
) -> Vec<([f64; 2], [f64; 2])> {
    let placement = asset.placement(camera, SIDE, SIDE);
    let camera = halo4d::internals::Camera::new(camera, &placement, SIDE, SIDE, 0.0).unwrap();
    let mut segments = Vec::new();
    for (points, closed) in lines {
        let p: Vec<[f64; 2]> = points
            .iter()
            .filter_map(|&q| camera.project(q, SIDE, SIDE).map(|(xy, _)| xy))
            .collect();
        segments.extend(p.windows(2).map(|w| (w[0], w[1])));
        if closed && p.len() > 2 {
            segments.push((p[p.len() - 1], p[0]));
        }
    }
    segments
}

/// Whether the pixel centre (x + 0.5, y + 0.5) lies within `reach` pixels of a segment.
fn near(segments: &[([f64; 2], [f64; 2])], x: u32, y: u32, reach: f64) -> bool {
    let p = [f64::from(x) + 0.5, f64::from(y) + 0.5];
    segments.iter().any(|&(a, b)| {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let len2 = dx * dx + dy * dy;
        let s = if len2 > 0.0 {
            (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (a[0] + s * dx - p[0]).hypot(a[1] + s * dy - p[1]) <= reach
    })
}

/// The pixels where frames `a` and `b` of `SIDE` x `SIDE` differ: x, y and `a`'s colour.
fn changed_pixels<'a>(
    a: &'a viewer::Frame,
    b: &'a viewer::Frame,
) -> impl Iterator<Item = (u32, u32, &'a [u8])> + 'a {
    a.picture
        .rgb
        .chunks(3)
        .zip(b.picture.rgb.chunks(3))
        .enumerate()
        .filter(|(_, (p, q))| p != q)
        .map(|(i, (p, _))| (i as u32 % SIDE, i as u32 / SIDE, p))
}

/// Seeded 4D rotations: each of the six planes turned by up to 35 degrees either way.
fn seeded_rotations(seed: u64, count: usize) -> Vec<Rotation4> {
    let mut rng = Rng(seed);
    let mut angle = || (rng.unit() - 0.5) * 70.0;
    (0..count)
        .map(|_| Rotation4 {
            xy: angle(),
            xz: angle(),
            xw: angle(),
            yz: angle(),
            yw: angle(),
            zw: angle(),
        })
        .collect()
}

#[test]
fn every_fixture_turned_in_4d_on_the_gpu_matches_the_exact_render_of_its_rotated_scene() {
    let gpu = gpu();
    let mut worst = (0.0f64, String::new());
    let (mut shrunk, mut vertices) = (0, 0);
    for (k, path) in fixture_scenes().into_iter().enumerate() {
        let scene = Scene::load(&path).unwrap();
        let model = Model::new(scene.clone()).unwrap_or_else(|e| panic!("{}: {e}", scene.name));
        for rotation in seeded_rotations(k as u64 + 1, 3) {
            // Added to the scene's own angles, as `--rotate` adds them.
            let mut view = scene.view;
            for (name, a) in rotation.planes() {
                *view.rotation.angle_mut(name).unwrap() += a;
            }
            let found = viewer::compare_turned(
                gpu,
                &model,
                &view,
                &settings(&scene, HaloMode::Grid, 256),
                &[256],
                &mut |_| {},
            )
            .unwrap_or_else(|e| panic!("{} turned {rotation:?}: {e}", scene.name));
            shrunk += found.shrunk;
            vertices += found.vertices;
            // Where the sliced halo depth itself is off (steep w in a 4D perspective close
            // to the eye), the measure is the viewer on the build's own `.glb` of this view:
            // the GPU's halos must do as well as the build's, to half a percent and a tenth
            // of the share of the vertices where the build shrank rho.
            let mut allowed = 0.02;
            if found.rows.iter().any(|r| r.verdict_differs >= allowed) {
                let turned = Scene {
                    view,
                    ..scene.clone()
                };
                let dir = tempfile::tempdir().unwrap();
                let (_, asset) = exported(&turned, dir.path());
                let imported = halo4d::import::read_scene_glb(
                    &std::fs::read(dir.path().join(format!("{}.glb", turned.name))).unwrap(),
                )
                .unwrap();
                let (_, rows) = viewer::compare(
                    gpu,
                    &imported,
                    &asset,
                    &settings(&scene, HaloMode::Grid, 256),
                    &[256],
                    &mut |_| {},
                )
                .unwrap();
                let built = rows.iter().map(|r| r.verdict_differs).fold(0.0, f64::max);
                eprintln!(
                    "{}: the build's .glb in this view differs on {:.3}%",
                    scene.name,
                    built * 100.0
                );
                // The GPU's halos have the full rho where the build shrank it (its
                // `shrunk` vertices, the only places they may differ from the build's):
                // a tenth of the share of those vertices more.
                let shrunk_share = found.shrunk as f64 / found.vertices.max(1) as f64;
                allowed = allowed.max(built + 0.005 + 0.1 * shrunk_share);
            }
            for row in &found.rows {
                eprintln!(
                    "{:<26} {:>6.1} {:>6.1} {:>6.1} {:>6.1} {:>6.1} {:>6.1} {}: {:.3}%",
                    scene.name,
                    view.rotation.xy,
                    view.rotation.xz,
                    view.rotation.xw,
                    view.rotation.yz,
                    view.rotation.yw,
                    view.rotation.zw,
                    row.mode.name(),
                    row.verdict_differs * 100.0
                );
                assert!(
                    row.verdict_differs < allowed,
                    "{} turned by {rotation:?} ({} mode): the verdict differs on {:.2}% of covered pixels",
                    scene.name,
                    row.mode.name(),
                    row.verdict_differs * 100.0
                );
                if row.verdict_differs > worst.0 {
                    worst = (
                        row.verdict_differs,
                        format!("{} ({})", scene.name, row.mode.name()),
                    );
                }
            }
        }
    }
    eprintln!(
        "largest verdict difference: {:.3}% ({}); the build shrank rho at {shrunk} of {vertices} vertices",
        worst.0 * 100.0,
        worst.1
    );
}

#[test]
fn the_halos_rebuilt_on_the_gpu_conform_in_every_view() {
    let gpu = gpu();
    let mut inverted = (0, 0);
    for (k, path) in fixture_scenes().into_iter().enumerate() {
        let scene = Scene::load(&path).unwrap();
        let model = Model::new(scene.clone()).unwrap();
        for rotation in seeded_rotations(100 + k as u64, 2) {
            let mut view = scene.view;
            for (name, a) in rotation.planes() {
                *view.rotation.angle_mut(name).unwrap() += a;
            }
            let renderer =
                viewer::Renderer::for_model(gpu, &model, &view, viewer::OFFSCREEN_FORMAT).unwrap();
            let meshes = model.halo_meshes(renderer.asset());
            assert_eq!(
                meshes.iter().map(|m| m.tets.len()).sum::<usize>(),
                6 * model.triangle_count(),
                "{}: six tetrahedra per prism, none inserted",
                scene.name
            );
            for (i, mesh) in meshes.iter().enumerate() {
                let stats = halo4d::check::check(mesh);
                let name = format!("{} surface {i} turned by {rotation:?}", scene.name);
                assert_eq!(
                    stats.degenerate + stats.duplicate_tets,
                    0,
                    "{name}: {stats:?}"
                );
                assert_eq!(stats.overshared_faces, 0, "{name}: {stats:?}");
                assert_eq!(stats.quad_mismatches, 0, "{name}: {stats:?}");
                assert_eq!(stats.missing_offset_faces, 0, "{name}: {stats:?}");
                assert_eq!(stats.unexpected_boundary_faces, 0, "{name}: {stats:?}");
                assert_eq!(stats.missing_surface_faces, 0, "{name}: {stats:?}");
                inverted.0 += stats.inverted + stats.flat;
                inverted.1 += stats.tets;
            }
        }
    }
    // Where rho is not shrunk, offsets can fold: counted, not refused.
    eprintln!(
        "inverted or flat: {} of {} tetrahedra",
        inverted.0, inverted.1
    );
}

/// The default fixture, exported, with its built products.
fn default_export() -> (Scene, tempfile::TempDir, halo4d::Built, Asset) {
    let scene = Scene::load(&crate::common::fixture("scenes/default.json")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let (built, asset) = exported(&scene, dir.path());
    (scene, dir, built, asset)
}

#[test]
fn the_grid_is_built_once_per_slice_count_and_every_camera_reuses_it() {
    let gpu = gpu();
    let (scene, _dir, built, asset) = default_export();
    let mut renderer =
        viewer::Renderer::new(gpu, &asset, wgpu::TextureFormat::Rgba8UnormSrgb).unwrap();
    let mut s = settings(&scene, HaloMode::Grid, 128);
    let first = renderer.read_frame(gpu, &s).unwrap();
    assert!(
        first.times.grid_ms.is_some(),
        "the first frame builds the grid"
    );
    s.camera.azimuth += 90.0;
    let turned = renderer.read_frame(gpu, &s).unwrap();
    assert_eq!(turned.times.grid_ms, None, "a new camera reuses the grid");
    assert_ne!(first.picture, turned.picture, "the camera turned");
    s.render.slices = 256;
    assert!(
        renderer
            .read_frame(gpu, &s)
            .unwrap()
            .times
            .grid_ms
            .is_some()
    );
    // The view mode slices per frame and builds no grid.
    s.mode = HaloMode::View;
    assert_eq!(renderer.read_frame(gpu, &s).unwrap().times.grid_ms, None);
    // 512 slices: a grid larger than one storage binding on lavapipe (128 MiB), built in
    // bands of layers, still agrees with the exact render.
    s.mode = HaloMode::Grid;
    s.render.slices = 512;
    s.camera = scene.camera;
    let fine = renderer.read_frame(gpu, &s).unwrap();
    let differs = verdict_differs(&exact_distances(&scene, &built), &distances(&fine), SAME);
    eprintln!("default scene, grid of 512 slices: {:.3}%", differs * 100.0);
    assert!(differs < 0.01, "{:.2}%", differs * 100.0);
}

#[test]
fn curves_colour_and_transparency_toggle_what_they_should() {
    let gpu = gpu();
    let (scene, _dir, built, asset) = default_export();
    let base = settings(&scene, HaloMode::Grid, 256);
    let shot = |s: &ViewSettings| viewer::screenshot(gpu, &asset, s).unwrap();
    let with = shot(&base);
    let without = shot(&ViewSettings {
        render: RenderSettings {
            curves: false,
            ..base.render
        },
        ..base
    });
    let bare = shot(&ViewSettings {
        render: RenderSettings {
            curves: false,
            silhouettes: false,
            ..base.render
        },
        ..base
    });
    // Silhouettes are drawn where the surfaces turn away: the pixels they change are within
    // two pixels of a jump in distance (to the background, or to a surface behind by more
    // than a hundredth of the scene's size), in the picture with halos or in the one
    // without (where a halo has cut away the sheet in front of a silhouette, the CPU
    // renderer draws it too).
    let unhidden = shot(&ViewSettings {
        render: RenderSettings {
            curves: false,
            silhouettes: false,
            halos: false,
            ..base.render
        },
        ..base
    });
    let jump = {
        let (lo, hi) = asset.bounds;
        0.01 * (hi - lo).length()
    };
    let at = |frame: &viewer::Frame, x: i64, y: i64| {
        let (x, y) = (x.clamp(0, SIDE as i64 - 1), y.clamp(0, SIDE as i64 - 1));
        f64::from(frame.distance[(y * SIDE as i64 + x) as usize])
    };
    let breaks = |a: f64, b: f64| a.is_finite() != b.is_finite() || (a - b).abs() > jump;
    let near_jump = |x: i64, y: i64| {
        [&bare, &unhidden].iter().any(|f| {
            (-2..=2).any(|dy| {
                (-2..=2).any(|dx| {
                    let (px, py) = (x + dx, y + dy);
                    breaks(at(f, px, py), at(f, px + 1, py))
                        || breaks(at(f, px, py), at(f, px, py + 1))
                })
            })
        })
    };
    let (mut outlined, mut at_jump) = (0u32, 0u32);
    for (x, y, _) in changed_pixels(&without, &bare) {
        outlined += 1;
        at_jump += u32::from(near_jump(i64::from(x), i64::from(y)));
    }
    assert!(
        outlined > 200,
        "the silhouettes are drawn ({outlined} pixels)"
    );
    // Where a silhouette passes in front of a sheet it crosses, the jump behind it shrinks
    // to nothing: a few pixels there.
    assert!(
        f64::from(at_jump) >= 0.95 * f64::from(outlined),
        "{} of {outlined} silhouette pixels away from every contour",
        outlined - at_jump
    );
    // Every pixel the curves change is on a projected curve segment: within half the
    // curves' 2.5-pixel width and a pixel.
    let segments = pixel_segments(
        &scene.camera,
        &asset,
        built
            .curves
            .curves
            .iter()
            .map(|c| (c.points.iter().map(|p| p.position).collect(), c.closed)),
    );
    let mut changed = 0;
    for (x, y, _) in changed_pixels(&with, &without) {
        changed += 1;
        assert!(
            near(&segments, x, y, 2.25),
            "pixel ({x}, {y}) changed away from every curve"
        );
    }
    // The default view hides most of its curves inside the outer sheet: a dozen or so
    // pixels show (14 on the current mesh).
    assert!(changed > 0, "the curves are drawn ({changed} pixels)");
    // Grey: every pixel neutral; colour by w: not.
    let neutral = |p: &viewer::Frame| {
        p.picture
            .rgb
            .chunks(3)
            .all(|c| c[0].abs_diff(c[1]) <= 1 && c[1].abs_diff(c[2]) <= 1)
    };
    assert!(!neutral(&without));
    assert!(neutral(&shot(&ViewSettings {
        render: RenderSettings {
            curves: false,
            ..base.render
        },
        colour_by_w: false,
        ..base
    })));
    // Transparent surfaces let the background through: the picture is lighter, and no
    // distance is reported.
    let clear = shot(&ViewSettings {
        render: RenderSettings {
            curves: false,
            silhouettes: false,
            ..base.render
        },
        transparent: true,
        ..base
    });
    let brightness = |f: &viewer::Frame| f.picture.rgb.iter().map(|&c| u64::from(c)).sum::<u64>();
    assert!(brightness(&clear) > brightness(&bare));
    assert!(clear.distance.iter().all(|d| d.is_infinite()));
    assert!(bare.distance.iter().any(|d| d.is_finite()));
}

/// `bytes` (a `.glb`) with its JSON chunk changed by `edit`.
fn edited(bytes: &[u8], edit: impl FnOnce(&mut serde_json::Value)) -> Vec<u8> {
    let u32_at = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
    let json_len = u32_at(12);
    let mut json: serde_json::Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    edit(&mut json);
    let bin = &bytes[20 + json_len.next_multiple_of(4) + 8..];
    glb(&json, bin)
}

/// A `.glb` of `json` and `bin`.
fn glb(json: &serde_json::Value, bin: &[u8]) -> Vec<u8> {
    halo4d::export::glb_container(serde_json::to_vec(json).unwrap(), bin.to_vec())
}

/// Loading `bytes` fails with a message containing every one of `words`.
fn refused(bytes: &[u8], words: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.glb");
    std::fs::write(&path, bytes).unwrap();
    let message = match Asset::load(&path) {
        Ok(_) => panic!("loaded a file that should be refused ({words:?})"),
        Err(e) => e.to_string(),
    };
    for w in words {
        assert!(message.contains(w), "`{w}` not in: {message}");
    }
}

#[test]
fn malformed_and_foreign_files_get_a_clear_message() {
    let (scene, dir, _, asset) = default_export();
    let bytes = std::fs::read(dir.path().join(format!("{}.glb", scene.name))).unwrap();
    refused(&bytes[..bytes.len() / 2], &["bad.glb", "truncated"]);
    refused(b"not a glb at all", &["wrong magic"]);
    // A foreign file: meshes without halo4d's extras.
    let foreign = edited(&bytes, |j| {
        for m in j["meshes"].as_array_mut().unwrap() {
            m.as_object_mut().unwrap().remove("extras");
        }
        j["asset"].as_object_mut().unwrap().remove("extras");
    });
    refused(&foreign, &["no surface", "halo4d build"]);
    // A scene camera that is not one.
    let camera = edited(&bytes, |j| {
        j["asset"]["extras"]["halo4d"]["scene"]["camera"] = serde_json::json!({"azimuth": "east"});
    });
    refused(&camera, &["camera", "azimuth"]);
    // No halo: the surfaces load, are named, and nothing is hidden.
    let no_halo = edited(&bytes, |j| {
        for m in j["meshes"].as_array_mut().unwrap() {
            if let Some(e) = m.get_mut("extras").and_then(|e| e.as_object_mut()) {
                e.remove("halo");
            }
        }
    });
    let path = dir.path().join("no-halo.glb");
    std::fs::write(&path, &no_halo).unwrap();
    let bare = Asset::load(&path).unwrap();
    assert_eq!(bare.tet_count(), 0);
    assert!(!bare.surfaces_without_halo.is_empty());
    let s = ViewSettings {
        render: RenderSettings {
            curves: false,
            ..settings(&scene, HaloMode::Grid, 64).render
        },
        ..settings(&scene, HaloMode::Grid, 64)
    };
    let gpu = gpu();
    let off = viewer::screenshot(
        gpu,
        &asset,
        &ViewSettings {
            render: RenderSettings {
                halos: false,
                ..s.render
            },
            ..s
        },
    )
    .unwrap();
    assert_eq!(
        viewer::screenshot(gpu, &bare, &s).unwrap().picture,
        off.picture
    );
}

#[test]
fn a_mesh_of_ten_million_triangles_is_refused_before_the_gpu_sees_it() {
    let triangles = 10_000_000u32;
    let mut bin = Vec::new();
    for p in [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        bin.extend(p.iter().flat_map(|x| x.to_le_bytes()));
    }
    bin.extend([0f32; 3].iter().flat_map(|x| x.to_le_bytes()));
    let indices_at = bin.len();
    bin.reserve(triangles as usize * 12);
    for _ in 0..triangles {
        bin.extend([0u32, 1, 2].iter().flat_map(|x| x.to_le_bytes()));
    }
    let json = serde_json::json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 36},
            {"buffer": 0, "byteOffset": 36, "byteLength": 12},
            {"buffer": 0, "byteOffset": indices_at, "byteLength": triangles as usize * 12},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
            {"bufferView": 1, "componentType": 5126, "count": 3, "type": "SCALAR"},
            {"bufferView": 2, "componentType": 5125, "count": triangles * 3, "type": "SCALAR"},
        ],
        "meshes": [{
            "name": "huge",
            "extras": {"surface": "plane"},
            "primitives": [{"attributes": {"POSITION": 0, "_W": 1}, "indices": 2}],
        }],
    });
    refused(
        &glb(&json, &bin),
        &["10000000", "surface triangles", "coarser tolerance"],
    );
}

#[test]
fn the_binary_writes_a_screenshot_and_refuses_bad_flags() {
    let (scene, dir, _, _) = default_export();
    let glb = dir.path().join(format!("{}.glb", scene.name));
    let run = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_halo4d-view"))
            .arg(&glb)
            .args(args)
            .output()
            .unwrap()
    };
    let png = dir.path().join("shot.png");
    let out = run(&[
        "--headless",
        "--screenshot",
        png.to_str().unwrap(),
        "--size",
        "96x64",
        "--slices",
        "64",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let image = image::open(&png).unwrap();
    assert_eq!((image.width(), image.height()), (96, 64));
    // The `.glb` carries its 4D mesh and scene: it can be sliced, and the slice shows.
    let sliced = dir.path().join("sliced.png");
    let out = run(&[
        "--headless",
        "--screenshot",
        sliced.to_str().unwrap(),
        "--size",
        "96x64",
        "--slices",
        "64",
        "--hyperplane",
        "-0.5",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_ne!(image, image::open(&sliced).unwrap());
    for (args, words) in [
        (&["--headless"][..], &["--screenshot"][..]),
        (
            &["--headless", "--screenshot", "x.png", "--size", "0x64"],
            &["size"],
        ),
        (
            &["--headless", "--screenshot", "x.png", "--slices", "1"],
            &["slices"],
        ),
        (
            &["--headless", "--screenshot", "x.png", "--elevation", "95"],
            &["elevation"],
        ),
        (
            &["--headless", "--screenshot", "x.png", "--hyperplane", "9"],
            &["hyperplane", "level 9 is outside the surfaces' heights"],
        ),
        (
            &["--bench", "--hyperplane", "0"],
            &["--hyperplane", "not in --bench"],
        ),
    ] {
        let out = run(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains("error: "), "{err}");
        for w in words {
            assert!(err.contains(w), "{args:?}: `{w}` not in {err}");
        }
        assert!(!err.contains("panicked"), "{err}");
    }
    // --bench prints a row per mode and slice count.
    let out = run(&["--bench", "--frames", "2", "--size", "64x48"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    for mode in ["grid", "view"] {
        for n in [64, 128, 256, 512] {
            assert!(
                text.contains(&format!("| {mode} | {n} |")),
                "no {mode} {n} row in {text}"
            );
        }
    }
}

#[test]
fn a_view_saved_in_the_explorer_builds_to_that_view_and_checks() {
    let dir = tempfile::tempdir().unwrap();
    let scene_path = crate::common::fixture("scenes/flat-torus.json");
    let view = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_halo4d-view"))
            .args(args)
            .current_dir(dir.path())
            .output()
            .unwrap()
    };
    let scene = Scene::load(&scene_path).unwrap();
    let out = view(&[
        scene_path.to_str().unwrap(),
        "--headless",
        "--save-scene",
        "turned.json",
        "--screenshot",
        "turned.png",
        "--size",
        "96x96",
        "--rotate",
        "xw=20",
        "--rotate",
        "YW=-35.5",
        "--rotate",
        "xw=5",
        "--azimuth",
        "60",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(image::open(dir.path().join("turned.png")).is_ok());
    // The view asked for: the scene's angles plus every --rotate of the plane.
    let mut expected = scene.view;
    expected.rotation.xw += 25.0;
    expected.rotation.yw -= 35.5;
    let saved = Scene::load(&dir.path().join("turned.json")).unwrap();
    assert_eq!(saved.name, "turned");
    assert_eq!(saved.view, expected);
    assert_eq!(saved.camera.azimuth, 60.0);
    let built = crate::common::halo4d(&["build", "turned.json"], dir.path());
    assert!(
        built.status.success(),
        "{}",
        String::from_utf8_lossy(&built.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(
        &std::fs::read(dir.path().join("exports/turned/report.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(
        report["scene"]["view"],
        serde_json::to_value(expected).unwrap(),
        "the build's view is the one on screen"
    );
    assert_eq!(report["verified"], true);
    let checked = crate::common::halo4d(&["check", "exports/turned"], dir.path());
    assert!(
        checked.status.success(),
        "{}",
        String::from_utf8_lossy(&checked.stdout)
    );

    // Bad --rotate values, and a .glb without the 4D mesh, get a clear error.
    let glb = std::fs::read(dir.path().join("exports/turned/turned.glb")).unwrap();
    let flat = dir.path().join("flat.glb");
    std::fs::write(&flat, without_4d(&glb)).unwrap();
    for (args, words) in [
        (
            vec!["--rotate", "qw=3"],
            &["qw", "xy, xz, xw, yz, yw or zw"][..],
        ),
        (vec!["--rotate", "xw"], &["PLANE=DEGREES"][..]),
        (vec!["--rotate", "xw=ten"], &["ten", "degrees"][..]),
        (
            vec![flat.to_str().unwrap(), "--rotate", "xw=3"],
            &["turns in 3D only", "no _X4", "open its scene file"][..],
        ),
    ] {
        let mut all = vec!["--headless", "--screenshot", "x.png"];
        all.extend(args.iter().copied());
        if !args[0].ends_with(".glb") {
            all.insert(0, scene_path.to_str().unwrap());
        }
        let out = view(&all);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_ne!(out.status.code(), Some(0), "{args:?}");
        for w in words {
            assert!(err.contains(w), "{args:?}: `{w}` not in {err}");
        }
        assert!(!err.contains("panicked"), "{err}");
    }
    assert!(!dir.path().join("x.png").exists());

    // --bench times the 4D turn (halos rebuilt every frame) apart from the 3D orbit.
    let out = view(&[
        scene_path.to_str().unwrap(),
        "--bench",
        "--frames",
        "2",
        "--size",
        "64x48",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    for motion in ["3D orbit", "4D turn"] {
        for n in [64, 512] {
            assert!(
                text.contains(&format!("| {motion} | view | {n} |")),
                "no {motion} {n} row in {text}"
            );
        }
    }
}

/// `bytes` (a scene's `.glb`) without the surfaces' 4D attributes.
fn without_4d(bytes: &[u8]) -> Vec<u8> {
    edited(bytes, |json| {
        for mesh in json["meshes"].as_array_mut().unwrap() {
            for p in mesh["primitives"].as_array_mut().unwrap() {
                let attributes = p["attributes"].as_object_mut().unwrap();
                // `_X4` … `_WV4`.
                attributes.retain(|name, _| !name.ends_with('4'));
            }
        }
    })
}

#[test]
fn a_glb_turns_in_4d_as_its_scene_does_and_one_without_the_4d_mesh_in_3d() {
    let gpu = gpu();
    let (scene, dir, built, _) = default_export();
    let path = dir.path().join(format!("{}.glb", scene.name));
    // The file's 4D mesh is the sampled one, in f32.
    let imported = halo4d::import::read_scene_glb(&std::fs::read(&path).unwrap()).unwrap();
    for (s, product) in imported.surfaces.iter().zip(&built.surfaces) {
        let mesh = s.mesh_4d.as_ref().unwrap_or_else(|e| panic!("{e}"));
        for (file, sampled) in [
            (&mesh.positions, &product.mesh.positions),
            (&mesh.tangent_u, &product.mesh.tangent_u),
            (&mesh.tangent_v, &product.mesh.tangent_v),
        ] {
            assert_eq!(file.len(), sampled.len());
            assert!(
                file.iter()
                    .zip(sampled)
                    .all(|(a, b)| *a == b.as_vec4().as_dvec4())
            );
        }
        assert_eq!(mesh.triangles, product.mesh.triangles);
    }
    let (from_file, notes) =
        viewer::Source::open(Some(&path), halo4d::progress::Job::SILENT).unwrap();
    assert!(notes.is_empty(), "{notes:?}");
    assert!(matches!(from_file, viewer::Source::Model(_)));
    let from_scene = viewer::Source::Model(Model::new(scene.clone()).unwrap().into());
    let mut view = scene.view;
    view.rotation.xw += 25.0;
    view.rotation.zw -= 40.0;
    let s = ViewSettings {
        render: RenderSettings {
            curves: false,
            ..settings(&scene, HaloMode::Grid, 128).render
        },
        ..settings(&scene, HaloMode::Grid, 128)
    };
    let frames = [&from_file, &from_scene].map(|source| {
        distances(&viewer::screenshot_of(gpu, source, Some(&view), &s, None).unwrap())
    });
    let differs = verdict_differs(&frames[0], &frames[1], SAME);
    assert!(
        differs < 0.001,
        "the file and the scene differ on {:.3}%",
        differs * 100.0
    );

    // Without the 4D attributes (a program that re-saved the file may drop them): in 3D,
    // with the reason.
    let flat = dir.path().join("flat.glb");
    std::fs::write(&flat, without_4d(&std::fs::read(&path).unwrap())).unwrap();
    let (source, notes) = viewer::Source::open(Some(&flat), halo4d::progress::Job::SILENT).unwrap();
    assert!(matches!(source, viewer::Source::Asset(_)));
    assert!(
        notes
            .iter()
            .any(|n| n.contains("turns in 3D only") && n.contains("_X4")),
        "{notes:?}"
    );
}

#[test]
fn supersampling_draws_what_the_cpu_renderer_draws_with_as_many_samples() {
    let gpu = gpu();
    let (scene, _dir, built, asset) = default_export();
    let cpu = |samples| {
        let settings = RenderSettings {
            width: SIDE,
            height: SIDE,
            samples,
            mode: RenderMode::Exact,
            ..scene.render
        };
        let parts = built.parts(&scene.halo);
        render_with_depth(&parts, &settings, &scene.camera).unwrap()
    };
    let (reference, depth) = cpu(4);
    let gpu_at = |samples| {
        viewer::screenshot(
            gpu,
            &asset,
            &ViewSettings {
                render: RenderSettings {
                    samples,
                    ..settings(&scene, HaloMode::Grid, 256).render
                },
                ..settings(&scene, HaloMode::Grid, 256)
            },
        )
        .unwrap()
    };
    let mean_diff = |p: &halo4d::render::Picture| {
        p.rgb
            .iter()
            .zip(&reference.rgb)
            .map(|(&a, &b)| f64::from(a.abs_diff(b)))
            .sum::<f64>()
            / p.rgb.len() as f64
    };
    let (one, four) = (gpu_at(1), gpu_at(4));
    let (d1, d4) = (mean_diff(&one.picture), mean_diff(&four.picture));
    eprintln!(
        "mean difference from the CPU's 4-sample picture: 1 sample {d1:.2}, 4 samples {d4:.2} (of 255)"
    );
    assert!(
        d4 < d1 * 0.8,
        "4 samples ({d4:.2}) are not closer than 1 ({d1:.2})"
    );
    // The distances come from the sample the CPU renderer takes them from.
    let differs = verdict_differs(&depth, &distances(&four), SAME);
    assert!(differs < 0.02, "{:.2}%", differs * 100.0);
    assert!(
        viewer::screenshot(
            gpu,
            &asset,
            &ViewSettings {
                render: RenderSettings {
                    samples: 3,
                    ..settings(&scene, HaloMode::Grid, 64).render
                },
                ..settings(&scene, HaloMode::Grid, 64)
            }
        )
        .is_err_and(|e| e.to_string().contains("samples"))
    );
}

// ---------------------------------------------------------------- stipples

/// Side of the tiles whose ink the stipple comparisons measure.
const TILE: usize = 32;

/// Per `TILE` x `TILE` tile (row-major), the mean ink of a stipple picture: per pixel, how
/// far its linear grey is from the white background towards the ink (0.02), in [0, 1].
fn tile_ink(p: &halo4d::render::Picture) -> Vec<f64> {
    let (w, h) = (p.width as usize, p.height as usize);
    let linear = |c: u8| {
        let c = f64::from(c) / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    };
    let (tx, ty) = (w.div_ceil(TILE), h.div_ceil(TILE));
    let mut sum = vec![(0.0, 0usize); tx * ty];
    for y in 0..h {
        for x in 0..w {
            let i = 3 * (y * w + x);
            let grey = (0..3).map(|c| linear(p.rgb[i + c])).sum::<f64>() / 3.0;
            let tile = &mut sum[(y / TILE) * tx + x / TILE];
            tile.0 += ((1.0 - grey) / 0.98).clamp(0.0, 1.0);
            tile.1 += 1;
        }
    }
    sum.into_iter().map(|(s, n)| s / n as f64).collect()
}

/// The largest difference of tile ink between the GPU's stipple picture of `scene` in the
/// 4D `view` (its own when `None`, turned on the GPU) and the CPU renderer's (exact mode,
/// built in that view), without lines, and the mean ink of the CPU's picture.
fn stipple_tile_difference(scene: &Scene, view: Option<&halo4d::view::View>) -> (f64, f64) {
    let mut scene = scene.clone();
    scene.render.style = halo4d::render::Style::Stipple;
    scene.render.curves = false;
    scene.render.silhouettes = false;
    scene.render.stipple.count = scene.render.stipple.count.min(100_000);
    scene.outputs.glb = false;
    scene.outputs.vtk = false;
    scene.outputs.verify = Some(false);
    let source = viewer::Source::Model(Model::new(scene.clone()).unwrap().into());
    if let Some(v) = view {
        scene.view = *v;
    }
    let built = crate::common::built(&scene).unwrap();
    let cpu = built
        .render(
            &scene.halo,
            &RenderSettings {
                width: SIDE,
                height: SIDE,
                mode: RenderMode::Exact,
                ..scene.render
            },
            &scene.camera,
        )
        .unwrap();
    let gpu_frame = viewer::screenshot_of(
        gpu(),
        &source,
        view,
        &ViewSettings {
            render: RenderSettings {
                style: halo4d::render::Style::Stipple,
                stipple: scene.render.stipple,
                curves: false,
                silhouettes: false,
                ..settings(&scene, HaloMode::Grid, 256).render
            },
            ..settings(&scene, HaloMode::Grid, 256)
        },
        None,
    )
    .unwrap_or_else(|e| panic!("{}: {e}", scene.name));
    let (a, b) = (tile_ink(&cpu), tile_ink(&gpu_frame.picture));
    let worst = a
        .iter()
        .zip(&b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    (worst, a.iter().sum::<f64>() / a.len() as f64)
}

#[test]
fn stipples_on_the_gpu_ink_every_tile_as_the_cpu_renderer_does() {
    let mut worst = (0.0f64, String::new());
    for name in ["default", "flat-torus", "klein-bottle-stipples"] {
        let scene = Scene::load(&crate::common::fixture(&format!("scenes/{name}.json"))).unwrap();
        let (differs, ink) = stipple_tile_difference(&scene, None);
        eprintln!(
            "{name:<24} mean ink {:.3}, largest tile difference {:.4}",
            ink, differs
        );
        assert!(
            ink > 0.02,
            "{name}: the CPU's picture has almost no ink ({ink})"
        );
        assert!(
            differs < 0.05,
            "{name}: a {TILE}x{TILE} tile's ink differs by {differs:.3}"
        );
        if differs > worst.0 {
            worst = (differs, name.into());
        }
    }
    eprintln!("largest tile difference: {:.4} ({})", worst.0, worst.1);
}

#[test]
fn stipples_turned_in_4d_on_the_gpu_ink_as_the_cpu_render_of_the_rotated_scene() {
    // The stipples stay on the mesh's triangles: after a 4D turn on the GPU they are placed
    // and thinned from the turned vertices as the CPU places them in the scene built in
    // that view.
    let scene = Scene::default_scene();
    for rotation in seeded_rotations(7, 2) {
        let mut view = scene.view;
        for (name, a) in rotation.planes() {
            *view.rotation.angle_mut(name).unwrap() += a;
        }
        let (differs, ink) = stipple_tile_difference(&scene, Some(&view));
        eprintln!("turned {rotation:?}: mean ink {ink:.3}, largest tile difference {differs:.4}");
        assert!(differs < 0.05, "turned {rotation:?}: {differs:.3}");
    }
}

#[test]
fn the_stipple_style_is_refused_for_a_glb_without_its_4d_mesh() {
    let (scene, dir, _, _) = default_export();
    let bytes = std::fs::read(dir.path().join(format!("{}.glb", scene.name))).unwrap();
    let path = dir.path().join("without-4d.glb");
    std::fs::write(&path, without_4d(&bytes)).unwrap();
    let (source, _) = viewer::Source::open(Some(&path), halo4d::progress::Job::SILENT).unwrap();
    assert!(matches!(source, viewer::Source::Asset(_)));
    let e = viewer::screenshot_of(
        gpu(),
        &source,
        None,
        &ViewSettings {
            render: RenderSettings {
                style: halo4d::render::Style::Stipple,
                ..settings(&scene, HaloMode::Grid, 64).render
            },
            ..settings(&scene, HaloMode::Grid, 64)
        },
        None,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("stipple") && e.contains("4D mesh"), "{e}");
    let e = viewer::screenshot_of(
        gpu(),
        &source,
        None,
        &settings(&scene, HaloMode::Grid, 64),
        Some(0.0),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("hyperplane") && e.contains("no 4D mesh"), "{e}");
}
