//! The stipple style: ink that follows the tone on a lit sphere at two picture sizes, the
//! same stipples after a small orbit, the halos' gaps along the flat torus's curves, and
//! every fixture drawn.

use crate::common::{fixture, fixture_scenes};
use glam::{DVec3, DVec4};
use halo4d::internals::{Camera, Drawn, Placement, tone};
use halo4d::render::stipples_drawn;
use halo4d::{
    Parts, Scene, SurfacePart, intersect::Curves, render::CameraSettings, render::RenderSettings,
    render::Style, stipple::Stipples,
};
use std::collections::BTreeSet;

/// A unit sphere of `lat` x `lon` quads (poles welded), with its outward normals.
fn sphere(lat: u32, lon: u32) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut p = vec![DVec3::Z, -DVec3::Z];
    for i in 1..lat {
        let theta = std::f64::consts::PI * f64::from(i) / f64::from(lat);
        for j in 0..lon {
            let phi = std::f64::consts::TAU * f64::from(j) / f64::from(lon);
            p.push(DVec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            ));
        }
    }
    let ring = |i: u32, j: u32| 2 + (i - 1) * lon + j % lon;
    let mut t = Vec::new();
    for j in 0..lon {
        t.push([0, ring(1, j), ring(1, j + 1)]);
        t.push([1, ring(lat - 1, j + 1), ring(lat - 1, j)]);
        for i in 1..lat - 1 {
            t.push([ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)]);
            t.push([ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)]);
        }
    }
    (p, t)
}

/// Per tone band (8 bands over [0, 1]): (pixels, mean target tone, mean ink) of a stipple
/// picture of the unit sphere at `side` pixels, over the pixels whose centre ray meets the
/// sphere well inside its outline.
fn sphere_bands(
    side: u32,
    set: &Stipples,
    positions: &[DVec3],
    triangles: &[[u32; 3]],
) -> Vec<(usize, f64, f64)> {
    let w = vec![0.0; positions.len()];
    let curves = Curves::default();
    let parts = Parts {
        surfaces: vec![SurfacePart {
            positions,
            w: &w,
            normals: positions,
            uv: None,
            triangles,
            stipples: Some(set),
        }],
        halos: vec![None],
        curves: &curves,
    };
    let settings = RenderSettings {
        style: Style::Stipple,
        width: side,
        height: side,
        curves: false,
        silhouettes: false,
        halos: false,
        ..RenderSettings::default()
    };
    let camera = CameraSettings {
        distance: Some(3.2),
        ..CameraSettings::default()
    };
    let picture = halo4d::render::render(&parts, &settings, &camera).unwrap();
    let bounds = (DVec3::splat(-1.0), DVec3::splat(1.0));
    let placement = Placement::new(&camera, bounds, std::iter::empty(), side, side, &[0.0]);
    let cam = Camera::new(&camera, &placement, side, side, 0.0).unwrap();
    let mut bands = vec![(0usize, 0.0, 0.0); 8];
    for y in 0..side {
        for x in 0..side {
            let sx = 2.0 * (f64::from(x) + 0.5) / f64::from(side) - 1.0;
            let sy = 1.0 - 2.0 * (f64::from(y) + 0.5) / f64::from(side);
            let (o, d) = cam.ray(sx, sy);
            // The unit sphere: |o + t d| = 1, nearest root.
            let b = o.dot(d);
            let disc = b * b - (o.length_squared() - 1.0);
            if disc <= 0.0 {
                continue;
            }
            let n = o + d * (-b - disc.sqrt());
            if n.dot(d).abs() < 0.3 {
                continue;
            }
            let target = tone(n, d, &cam);
            let at = 3 * (y * side + x) as usize;
            let srgb = f64::from(picture.rgb[at]) / 255.0;
            let linear = if srgb <= 0.04045 {
                srgb / 12.92
            } else {
                ((srgb + 0.055) / 1.055).powf(2.4)
            };
            // Ink is 0.02 on a white background.
            let ink = ((1.0 - linear) / 0.98).clamp(0.0, 1.0);
            let band = &mut bands[((target * 8.0) as usize).min(7)];
            band.0 += 1;
            band.1 += target;
            band.2 += ink;
        }
    }
    bands
        .into_iter()
        .map(|(n, t, i)| (n, t / n.max(1) as f64, i / n.max(1) as f64))
        .collect()
}

#[test]
fn ink_follows_the_tone_and_stays_when_the_picture_doubles() {
    let (positions, triangles) = sphere(48, 96);
    let p4: Vec<DVec4> = positions.iter().map(|p| p.extend(0.0)).collect();
    let set = Stipples::generate(&p4, &triangles, 600_000, 1);
    let small = sphere_bands(256, &set, &positions, &triangles);
    let large = sphere_bands(512, &set, &positions, &triangles);
    let mut checked = 0;
    for (k, (s, l)) in small.iter().zip(&large).enumerate() {
        eprintln!(
            "band {k}: {} / {} pixels, tone {:.3} / {:.3}, ink {:.3} / {:.3}",
            s.0, l.0, s.1, l.1, s.2, l.2
        );
        if s.0 < 300 {
            continue;
        }
        checked += 1;
        assert!(
            (l.2 - l.1).abs() <= 0.10,
            "band {k} at 512 px: ink {:.3} for tone {:.3}",
            l.2,
            l.1
        );
        assert!(
            (s.2 - s.1).abs() <= 0.10,
            "band {k} at 256 px: ink {:.3} for tone {:.3}",
            s.2,
            s.1
        );
        assert!(
            (l.2 - s.2).abs() <= 0.05,
            "band {k}: ink {:.3} at 256 px, {:.3} at 512 px",
            s.2,
            l.2
        );
    }
    assert!(checked >= 5, "only {checked} tone bands have pixels");
}

/// The default scene in stipple style at 400 px.
fn default_scene() -> (Scene, halo4d::Built) {
    let mut scene = Scene::default_scene();
    scene.render.style = Style::Stipple;
    (scene.render.width, scene.render.height) = (400, 400);
    let built = crate::common::built(&scene).unwrap();
    (scene, built)
}

#[test]
fn a_small_orbit_keeps_the_stipples_where_they_are() {
    let (scene, built) = default_scene();
    let parts = built.parts(&scene.halo);
    let before = stipples_drawn(&parts, &scene.render, &scene.camera).unwrap();
    let turned = CameraSettings {
        azimuth: scene.camera.azimuth + 2.0,
        ..scene.camera
    };
    let after = stipples_drawn(&parts, &scene.render, &turned).unwrap();
    let ids =
        |d: &[Drawn]| -> BTreeSet<(u32, u32)> { d.iter().map(|d| (d.surface, d.rank)).collect() };
    let (a, b) = (ids(&before), ids(&after));
    let kept = a.intersection(&b).count();
    let share = kept as f64 / a.len() as f64;
    eprintln!("{kept} of {} stipples kept after a 2-degree orbit", a.len());
    assert!(a.len() > 2000, "{} stipples drawn", a.len());
    assert!(
        share >= 0.9,
        "{kept} of {} stipples kept ({share:.3})",
        a.len()
    );
    // A kept stipple is at the same place on the surface.
    let place: std::collections::BTreeMap<(u32, u32), DVec3> = before
        .iter()
        .map(|d| ((d.surface, d.rank), d.position))
        .collect();
    for d in &after {
        if let Some(p) = place.get(&(d.surface, d.rank)) {
            assert_eq!(*p, d.position, "stipple {:?} moved", (d.surface, d.rank));
        }
    }
}

#[test]
fn the_far_sheet_has_no_stipples_in_the_gap_and_has_them_beyond() {
    let mut scene = Scene::load(&fixture("scenes/flat-torus.json")).unwrap();
    scene.render.style = Style::Stipple;
    (scene.render.width, scene.render.height) = (800, 800);
    scene.halo.rho = Some(0.03);
    let built = crate::common::built(&scene).unwrap();
    let parts = built.parts(&scene.halo);
    let without = RenderSettings {
        halos: false,
        ..scene.render
    };
    let on = stipples_drawn(&parts, &scene.render, &scene.camera).unwrap();
    let off = stipples_drawn(&parts, &without, &scene.camera).unwrap();
    let rho = &built.surfaces[0].halo.rho;
    let rho_max = rho.iter().copied().fold(0.0, f64::max);
    // The curves' segments whose ends cross clearly apart in w, with the same sheet over.
    let mut segments = Vec::new();
    let mut all = Vec::new();
    for c in &built.curves.curves {
        let n = c.points.len();
        let pairs = if c.closed { n } else { n.saturating_sub(1) };
        for k in 0..pairs {
            let (a, b) = (&c.points[k], &c.points[(k + 1) % n]);
            all.push((a.position, b.position));
            if a.dw() >= 0.3 && b.dw() >= 0.3 && a.near() == b.near() {
                // The near sheet's half-widths at both ends.
                let local = [a, b].into_iter().flat_map(|p| {
                    built.surfaces[0].mesh.triangles[p.faces[p.near()].triangle as usize]
                        .map(|v| rho[v as usize])
                });
                let (lo, hi) = local.fold((f64::INFINITY, 0.0f64), |(lo, hi), r| {
                    (lo.min(r), hi.max(r))
                });
                if lo > 0.0 {
                    segments.push((a, b, lo, hi));
                }
            }
        }
    }
    // The distance from x to segment [a, b], and where along it (0 at a, 1 at b).
    let to_segment = |x: DVec3, a: DVec3, b: DVec3| {
        let ab = b - a;
        let s = ((x - a).dot(ab) / ab.length_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
        ((a + ab * s - x).length(), s)
    };
    // The stipples of a far sheet in the gap of a crossing, and those beyond it (farther
    // than three half-widths from every curve, within six of a crossing).
    let classify = |drawn: &[Drawn]| {
        let mut gap = BTreeSet::new();
        let mut beyond = BTreeSet::new();
        for d in drawn {
            let nearest = all
                .iter()
                .map(|&(a, b)| to_segment(d.position, a, b).0)
                .fold(f64::INFINITY, f64::min);
            for &(a, b, lo, hi) in &segments {
                let (r, s) = to_segment(d.position, a.position, b.position);
                let (near, far) = (a.near(), 1 - a.near());
                let w_near = a.w[near] + (b.w[near] - a.w[near]) * s;
                let w_far = a.w[far] + (b.w[far] - a.w[far]) * s;
                let on_far = (d.w - w_far).abs() < (d.w - w_near).abs();
                if on_far && r < 0.4 * lo * scene.halo.delta_t {
                    gap.insert((d.surface, d.rank));
                }
                if on_far && r < 6.0 * hi && nearest > 3.0 * rho_max {
                    beyond.insert((d.surface, d.rank));
                }
            }
        }
        (gap, beyond)
    };
    let (gap_off, beyond_off) = classify(&off);
    let (gap_on, beyond_on) = classify(&on);
    eprintln!(
        "far stipples in the gaps: {} without halos, {} with; beyond: {} without, {} with",
        gap_off.len(),
        gap_on.len(),
        beyond_off.len(),
        beyond_off.intersection(&beyond_on).count()
    );
    assert!(
        gap_off.len() >= 10,
        "without halos only {} far stipples in the gaps",
        gap_off.len()
    );
    assert!(
        gap_on.is_empty(),
        "{} far stipples drawn in the gaps",
        gap_on.len()
    );
    let kept = beyond_off.intersection(&beyond_on).count();
    assert!(
        beyond_off.len() >= 50 && kept as f64 >= 0.95 * beyond_off.len() as f64,
        "beyond the gaps {kept} of {} far stipples drawn",
        beyond_off.len()
    );
}

#[test]
fn every_fixture_draws_in_stipples_in_both_modes() {
    for path in fixture_scenes() {
        let mut scene = Scene::load(&path).unwrap();
        scene.render.style = Style::Stipple;
        (scene.render.width, scene.render.height) = (200, 200);
        scene.render.stipple.count = 50_000;
        let built = crate::common::built(&scene).unwrap();
        for mode in [
            halo4d::render::RenderMode::Exact,
            halo4d::render::RenderMode::Slices,
        ] {
            let settings = RenderSettings {
                mode,
                curves: false,
                silhouettes: false,
                ..scene.render
            };
            let picture = built
                .render(&scene.halo, &settings, &scene.camera)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            let inked = picture.rgb.chunks(3).filter(|p| p[0] < 128).count();
            assert!(
                inked > 200,
                "{} ({mode:?}): {inked} dark pixels",
                path.display()
            );
        }
    }
}

#[test]
fn a_surface_without_stipples_is_a_clear_error() {
    let mut scene = Scene::load(&fixture("scenes/klein-bottle.json")).unwrap();
    (scene.render.width, scene.render.height) = (64, 64);
    let built = crate::common::built(&scene).unwrap();
    let stipple = RenderSettings {
        style: Style::Stipple,
        ..scene.render
    };
    let e = built
        .render(&scene.halo, &stipple, &scene.camera)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("render.style stipple") && e.contains("no stipples"),
        "{e}"
    );
}

#[test]
fn the_stipples_files_hold_the_pictures_stipples() {
    let path = fixture("scenes/klein-bottle-stipples.json");
    let scene = Scene::load(&path).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let report = halo4d::build(&scene, dir.path(), halo4d::progress::Job::SILENT).unwrap();
    assert_eq!(report.surfaces[0].stipples, Some(200_000));
    let built = crate::common::built(&scene).unwrap();
    let drawn = stipples_drawn(&built.parts(&scene.halo), &scene.render, &scene.camera).unwrap();
    assert!(drawn.len() > 1000, "{} stipples drawn", drawn.len());
    let name = &scene.name;

    // PLY: a point cloud, a vertex per drawn stipple, in order.
    let bytes = std::fs::read(dir.path().join(format!("{name}-stipples.ply"))).unwrap();
    let parser = ply_rs::parser::Parser::<ply_rs::ply::DefaultElement>::new();
    let ply = parser.read_ply(&mut bytes.as_slice()).unwrap();
    let vertices = &ply.payload["vertex"];
    assert_eq!(vertices.len(), drawn.len());
    assert!(!ply.payload.contains_key("face"));
    let float = |p: &ply_rs::ply::Property| match p {
        ply_rs::ply::Property::Float(x) => f64::from(*x),
        ply_rs::ply::Property::Int(x) => f64::from(*x),
        other => panic!("unexpected property {other:?}"),
    };
    for (v, d) in vertices.iter().zip(&drawn) {
        assert_eq!(float(&v["x"]), f64::from(d.position.x as f32));
        assert_eq!(float(&v["z"]), f64::from(d.position.z as f32));
        assert_eq!(float(&v["radius"]), f64::from(d.radius as f32));
        assert_eq!(float(&v["quality"]), f64::from(d.w as f32));
        assert_eq!(float(&v["rank"]), f64::from(d.rank));
        assert!(d.radius > 0.0);
    }

    // glTF: a mesh `stipples` of POINTS with _RADIUS and _W, positions y-up.
    let glb = std::fs::read(dir.path().join(format!("{name}.glb"))).unwrap();
    let gltf = gltf::Gltf::from_slice(&glb).unwrap();
    let blob = gltf.blob.as_deref().unwrap();
    let mesh = gltf
        .meshes()
        .find(|m| m.name() == Some("stipples"))
        .expect("a stipples mesh");
    let prim = mesh.primitives().next().unwrap();
    assert_eq!(prim.mode(), gltf::mesh::Mode::Points);
    let reader = prim.reader(|_| Some(blob));
    let positions: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
    assert_eq!(positions.len(), drawn.len());
    for (p, d) in positions.iter().zip(&drawn) {
        // glTF's y is halo4d's z, its z halo4d's -y.
        assert_eq!(
            *p,
            [
                d.position.x as f32,
                d.position.z as f32,
                -d.position.y as f32
            ]
        );
    }
    for (attr, expect) in [
        (
            "_RADIUS",
            drawn.iter().map(|d| d.radius).collect::<Vec<_>>(),
        ),
        ("_W", drawn.iter().map(|d| d.w).collect()),
    ] {
        let acc = prim
            .attributes()
            .find(|(s, _)| s.to_string() == attr)
            .unwrap_or_else(|| panic!("no {attr}"))
            .1;
        let view = acc.view().unwrap();
        let bytes = &blob[view.offset() + acc.offset()..][..acc.count() * 4];
        for (chunk, e) in bytes.chunks_exact(4).zip(&expect) {
            assert_eq!(
                f32::from_le_bytes(chunk.try_into().unwrap()),
                *e as f32,
                "{attr}"
            );
        }
    }
    // The build still checks clean: the point cloud is no surface.
    let checked = halo4d::check_dir(dir.path()).unwrap();
    assert!(checked.failures().is_empty(), "{:?}", checked.failures());
    assert_eq!(checked.halos.len(), 1);
}

#[test]
fn coloured_stipples_take_the_w_colours() {
    // The spun trefoil turned so that both ends of the w scale face the camera.
    let mut scene = Scene::default_scene();
    scene.view.rotation = halo4d::view::Rotation4::default();
    *scene.view.rotation.angle_mut("xw").unwrap() = 20.0;
    *scene.view.rotation.angle_mut("yw").unwrap() = 35.0;
    scene.camera = halo4d::render::CameraSettings::default();
    (scene.render.width, scene.render.height) = (400, 400);
    scene.render.style = Style::Stipple;
    let built = crate::common::built(&scene).unwrap();
    scene.render.stipple.colour = true;
    (scene.render.curves, scene.render.silhouettes) = (false, false);
    let picture = built
        .render(&scene.halo, &scene.render, &scene.camera)
        .unwrap();
    // Inked pixels of clearly different hues: blue (near) and orange (far) among them.
    let (mut blue, mut orange) = (0, 0);
    for p in picture.rgb.chunks(3) {
        let [r, g, b] = [p[0], p[1], p[2]].map(i32::from);
        blue += usize::from(b > r + 40 && b > g);
        orange += usize::from(r > b + 40 && r > g);
    }
    assert!(
        blue > 100 && orange > 100,
        "{blue} blue, {orange} orange pixels"
    );
}

#[test]
fn bad_stipple_settings_name_their_field() {
    for (json, field) in [
        (r#"{"stipple": {"size": 0.1}}"#, "render.stipple.size"),
        (r#"{"stipple": {"size": 40}}"#, "render.stipple.size"),
        (r#"{"stipple": {"count": 0}}"#, "render.stipple.count"),
        (
            r#"{"stipple": {"count": 99999999}}"#,
            "render.stipple.count",
        ),
        (r#"{"stipple": {"dots": 3}}"#, "dots"),
        (r#"{"style": "pointillist"}"#, "pointillist"),
    ] {
        let text = format!(
            r#"{{"name": "s", "surfaces": [{{"surface": {{"type": "flat_torus"}}}}], "render": {json}}}"#
        );
        let e = Scene::parse(&text, "s.json").unwrap_err().to_string();
        assert!(e.contains(field), "{json}: {e}");
    }
}
