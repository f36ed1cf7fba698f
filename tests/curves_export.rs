//! Intersection curves through their files: the .glb's `curves` mesh (tubes, and the exact
//! polylines as data, read by the gltf crate) and `<name>-curves.ply` (read by ply-rs) hold
//! exactly the curves of the build; a scene's
//! surfaces and halos read back from its .glb; `halo4d check DIR` passes a build and catches
//! faults planted in its .glb; unreadable folders are errors.

use crate::common::{
    Rng, assert_unreadable, fixture, fixture_scenes, halo4d, hard_scenes, with_json,
};
use glam::DVec3;
use halo4d::intersect::Curves;
use halo4d::{Built, Scene};
use halo4d::{import::ImportError, import::ImportedScene, import::read_scene_glb};
use ply_rs::ply::Property;
use serde_json::Value;
use std::path::Path;

/// Builds a scene into `dir`.
fn build(scene: &Scene, dir: &Path) -> Built {
    let built = crate::common::built(scene).unwrap();
    halo4d::write(scene, &built, dir).unwrap();
    built
}

/// The default scene (a spun trefoil: closed and open curves) and the patches fixture (open
/// curves ending at mesh boundaries).
fn scenes() -> Vec<Scene> {
    vec![
        Scene::default_scene(),
        Scene::load(&fixture("scenes/patches.json")).unwrap(),
    ]
}

/// The line segments the files must hold, numbering the points curve after curve: an open
/// curve of n points has n - 1, a closed one n (the last point joined to the first).
fn expected_segments(curves: &Curves) -> Vec<[u32; 2]> {
    let mut out = Vec::new();
    let mut base = 0;
    for c in &curves.curves {
        let n = c.points.len() as u32;
        assert!(n >= 2, "a curve of {n} points");
        for k in 0..n - 1 {
            out.push([base + k, base + k + 1]);
        }
        if c.closed {
            out.push([base + n - 1, base]);
        }
        base += n;
    }
    out
}

/// The values of a float SCALAR accessor.
fn scalars(blob: &[u8], acc: &gltf::Accessor) -> Vec<f32> {
    assert_eq!(acc.data_type(), gltf::accessor::DataType::F32);
    assert_eq!(acc.dimensions(), gltf::accessor::Dimensions::Scalar);
    let view = acc.view().unwrap();
    assert_eq!(view.stride(), None, "tightly packed");
    blob[view.offset() + acc.offset()..][..acc.count() * 4]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
        .collect()
}

/// The values of a float VEC3 accessor, in halo4d's frame (z up; the file's is glTF's).
fn points3(blob: &[u8], acc: &gltf::Accessor) -> Vec<DVec3> {
    assert_eq!(acc.data_type(), gltf::accessor::DataType::F32);
    assert_eq!(acc.dimensions(), gltf::accessor::Dimensions::Vec3);
    let view = acc.view().unwrap();
    blob[view.offset() + acc.offset()..][..acc.count() * 12]
        .chunks_exact(12)
        .map(|c| {
            let f =
                |k: usize| f64::from(f32::from_le_bytes(c[4 * k..4 * k + 4].try_into().unwrap()));
            DVec3::new(f(0), -f(2), f(1))
        })
        .collect()
}

/// Distance from `p` to the segment from `a` to `b`.
fn to_segment(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let d = b - a;
    let t = if d.length_squared() > 0.0 {
        ((p - a).dot(d) / d.length_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + t * d - p).length()
}

#[test]
fn the_glb_curves_mesh_is_tubes_around_every_curve_and_carries_the_exact_polylines() {
    let dir = tempfile::tempdir().unwrap();
    let (mut closed, mut open) = (0, 0);
    for scene in scenes() {
        let out = dir.path().join(&scene.name);
        let built = build(&scene, &out);
        let curves = built.shown_curves();
        let name = &scene.name;
        let points: Vec<_> = curves.curves.iter().flat_map(|c| &c.points).collect();
        assert!(!points.is_empty(), "{name}: no curves");
        closed += curves.curves.iter().filter(|c| c.closed).count();
        open += curves.curves.iter().filter(|c| !c.closed).count();

        let glb = std::fs::read(out.join(format!("{name}.glb"))).unwrap();
        let gltf = gltf::Gltf::from_slice(&glb).unwrap();
        let blob = gltf.blob.as_deref().unwrap();
        let mesh = gltf
            .meshes()
            .find(|m| m.name() == Some("curves"))
            .expect("a mesh `curves`");
        assert!(
            gltf.nodes()
                .any(|node| node.mesh().map(|m| m.index()) == Some(mesh.index())
                    && node.name() == Some("curves")),
            "{name}: the curves mesh has its own node"
        );
        assert!(
            gltf.scenes()
                .next()
                .unwrap()
                .nodes()
                .any(|n| n.mesh().map(|m| m.index()) == Some(mesh.index())),
            "{name}: the node is in the scene"
        );
        // No LINES anywhere: MeshLab crashes on them, Blender's renderers skip them.
        assert!(
            gltf.meshes()
                .flat_map(|m| m.primitives())
                .all(|p| p.mode() == gltf::mesh::Mode::Triangles)
        );
        assert_eq!(mesh.primitives().count(), 1);
        let prim = mesh.primitives().next().unwrap();
        let reader = prim.reader(|_| Some(blob));

        // The exact polylines: own accessors that the extras name.
        let extras: Value = serde_json::from_str(mesh.extras().as_ref().unwrap().get()).unwrap();
        let e = &extras["curves"];
        let r = &curves.report;
        assert_eq!(
            [&e["count"], &e["closed"], &e["open"], &e["points"]],
            [r.count, r.closed, r.open, r.points]
                .map(Value::from)
                .each_ref(),
            "{name}"
        );
        let radius = e["radius"].as_f64().unwrap();
        assert_eq!(radius, scene.outputs.curve_radius * built.diagonal);
        let own = |key: &str| {
            let acc = gltf
                .accessors()
                .nth(e["polylines"][key].as_u64().unwrap() as usize)
                .unwrap();
            assert_eq!(acc.name(), Some(format!("curves polyline {key}").as_str()));
            acc
        };
        let polyline = points3(blob, &own("POSITION"));
        let expected: Vec<DVec3> = points
            .iter()
            .map(|p| p.position.as_vec3().as_dvec3())
            .collect();
        assert_eq!(polyline, expected, "{name}");
        let curve_index: Vec<f32> = curves
            .curves
            .iter()
            .enumerate()
            .flat_map(|(k, c)| vec![k as f32; c.points.len()])
            .collect();
        let dw: Vec<f32> = points.iter().map(|p| p.dw() as f32).collect();
        let w: Vec<f32> = points.iter().map(|p| p.w[p.near()] as f32).collect();
        for (attr, want) in [("_DW", &dw), ("_CURVE", &curve_index), ("_W", &w)] {
            assert_eq!(&scalars(blob, &own(attr)), want, "{name}: {attr}");
        }
        // dw is the far sheet's w minus the near sheet's: never negative.
        assert!(
            points
                .iter()
                .all(|p| p.dw() >= 0.0 && p.w[1 - p.near()] - p.w[p.near()] == p.dw())
        );
        let indices = own("indices");
        assert_eq!(indices.data_type(), gltf::accessor::DataType::U32);
        let view = indices.view().unwrap();
        let segments: Vec<[u32; 2]> = blob[view.offset() + indices.offset()..]
            [..indices.count() * 4]
            .chunks_exact(8)
            .map(|c| {
                let u = |k: usize| u32::from_le_bytes(c[4 * k..4 * k + 4].try_into().unwrap());
                [u(0), u(1)]
            })
            .collect();
        assert_eq!(segments, expected_segments(curves), "{name}");

        // The tubes: every vertex within the radius of its own curve (brute force over the
        // curve's segments), carrying that curve's index and one of its points' dw and w;
        // a closed surface turned outward, enclosing about the octagonal prism's volume.
        let positions = points3(blob, &prim.get(&gltf::Semantic::Positions).unwrap());
        let attr = |a: &str| {
            scalars(
                blob,
                &prim
                    .attributes()
                    .find(|(s, _)| s.to_string() == a)
                    .unwrap_or_else(|| panic!("{name}: no {a}"))
                    .1,
            )
        };
        let (tube_curve, tube_dw, tube_w) = (attr("_CURVE"), attr("_DW"), attr("_W"));
        let mut first = 0;
        let starts: Vec<usize> = curves
            .curves
            .iter()
            .map(|c| {
                first += c.points.len();
                first - c.points.len()
            })
            .collect();
        for (v, p) in positions.iter().enumerate() {
            let k = tube_curve[v] as usize;
            let c = &curves.curves[k];
            let pts = &expected[starts[k]..starts[k] + c.points.len()];
            let d = pts
                .windows(2)
                .map(|s| to_segment(*p, s[0], s[1]))
                .chain(c.closed.then(|| to_segment(*p, pts[pts.len() - 1], pts[0])))
                .fold(f64::INFINITY, f64::min);
            assert!(
                d <= radius * (1.0 + 1e-4),
                "{name}: tube vertex {v} at {d}, radius {radius}"
            );
            let at = (starts[k]..starts[k] + c.points.len())
                .any(|i| dw[i] == tube_dw[v] && w[i] == tube_w[v]);
            assert!(
                at,
                "{name}: tube vertex {v}'s _DW and _W are none of its curve's"
            );
        }
        let normals: Vec<[f32; 3]> = reader.read_normals().expect("NORMAL").collect();
        assert_eq!(normals.len(), positions.len());
        let triangles: Vec<[u32; 3]> = reader
            .read_indices()
            .unwrap()
            .into_u32()
            .collect::<Vec<_>>()
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .collect();
        let mut edges = std::collections::HashMap::new();
        for t in &triangles {
            for k in 0..3 {
                *edges.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        assert!(
            edges
                .iter()
                .all(|(&(a, b), &n)| n == 1 && edges.get(&(b, a)) == Some(&1)),
            "{name}: the tubes are not closed surfaces turned one way"
        );
        let volume: f64 = triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| positions[i as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum();
        let length: f64 = segments
            .iter()
            .map(|s| (expected[s[0] as usize] - expected[s[1] as usize]).length())
            .sum();
        let prism = 2.0 * 2f64.sqrt() * radius * radius * length;
        assert!(
            (volume / prism - 1.0).abs() < 0.2,
            "{name}: the tubes enclose {volume}, the octagonal prism along the curves {prism}"
        );
    }
    assert!(closed > 0 && open > 0, "{closed} closed, {open} open");
}

fn float(p: &Property) -> f32 {
    match p {
        Property::Float(x) => *x,
        other => panic!("expected a float, got {other:?}"),
    }
}

fn double(p: &Property) -> f64 {
    match p {
        Property::Double(x) => *x,
        other => panic!("expected a double, got {other:?}"),
    }
}

fn int(p: &Property) -> i32 {
    match p {
        Property::Int(x) => *x,
        other => panic!("expected an int, got {other:?}"),
    }
}

#[test]
fn the_curves_ply_holds_the_same_points_and_edges() {
    let dir = tempfile::tempdir().unwrap();
    for scene in scenes() {
        let out = dir.path().join(&scene.name);
        let built = build(&scene, &out);
        let name = &scene.name;
        let report: Value =
            serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap();
        let file = format!("{name}-curves.ply");
        assert!(
            report["files"]
                .as_array()
                .unwrap()
                .contains(&Value::from(file.as_str())),
            "{name}: {file} not in the report's files"
        );
        let bytes = std::fs::read(out.join(&file)).unwrap();
        let parser = ply_rs::parser::Parser::<ply_rs::ply::DefaultElement>::new();
        let ply = parser.read_ply(&mut bytes.as_slice()).unwrap();
        assert_eq!(
            ply.header.encoding,
            ply_rs::ply::Encoding::BinaryLittleEndian
        );
        let vertices = &ply.payload["vertex"];
        let edges = &ply.payload["edge"];
        let mut k = 0;
        for (c, curve) in built.shown_curves().curves.iter().enumerate() {
            for p in &curve.points {
                let v = &vertices[k];
                let near = p.near();
                let xyz = [&v["x"], &v["y"], &v["z"]].map(double);
                assert_eq!(xyz, p.position.to_array(), "{name}: vertex {k}");
                assert_eq!(float(&v["quality"]), p.dw() as f32, "{name}: vertex {k}");
                assert_eq!(double(&v["w_near"]), p.w[near]);
                assert_eq!(double(&v["w_far"]), p.w[1 - near]);
                assert_eq!(float(&v["curve"]), c as f32);
                k += 1;
            }
        }
        assert_eq!(vertices.len(), k, "{name}");
        let got: Vec<[u32; 2]> = edges
            .iter()
            .map(|e| [int(&e["vertex1"]), int(&e["vertex2"])].map(|i| i as u32))
            .collect();
        assert_eq!(got, expected_segments(built.shown_curves()), "{name}");
    }
}

#[test]
fn check_on_the_written_glb_finds_exactly_what_the_build_found() {
    // Every fixture and every hard case builds verified. The build works on positions and w
    // rounded to f32, what the files store: the curves and the verification recomputed
    // from the .glb have the same counts.
    for path in fixture_scenes().into_iter().chain(hard_scenes()) {
        let scene = Scene::load(&path).unwrap();
        let built = crate::common::built(&scene).unwrap();
        let what = path.display();
        assert_eq!(built.failures(), Vec::<String>::new(), "{what}");
        let data: Vec<_> = built.surfaces.iter().map(|p| p.data(&scene.halo)).collect();
        let glb = halo4d::export::to_glb(&data, &built.curves, 0.01, &Value::Null).unwrap();
        let (curves, v) = halo4d::verify_scene(&read_scene_glb(&glb).unwrap());
        let counts = |r: &halo4d::intersect::CurvesReport| {
            [
                r.count,
                r.closed,
                r.open,
                r.points,
                r.segments,
                r.triple_points,
                r.unresolved,
            ]
        };
        assert_eq!(
            counts(&curves.report),
            counts(&built.curves.report),
            "{what}"
        );
        let untimed = |v: &halo4d::verify::Verification| halo4d::verify::Verification {
            ms: 0.0,
            ..v.clone()
        };
        assert_eq!(untimed(&v), untimed(&built.verification), "{what}");
    }
}

#[test]
fn without_curves_the_glb_has_no_curves_mesh_and_the_ply_is_empty_but_valid() {
    let scene = Scene::load(&fixture("scenes/patches.json")).unwrap();
    let built = crate::common::built(&scene).unwrap();
    let data: Vec<_> = built.surfaces.iter().map(|p| p.data(&scene.halo)).collect();
    let none = Curves::default();
    let glb = halo4d::export::to_glb(&data, &none, 0.01, &Value::Null).unwrap();
    let gltf = gltf::Gltf::from_slice(&glb).unwrap();
    assert_eq!(gltf.meshes().count(), 2);
    assert!(gltf.meshes().all(|m| m.name() != Some("curves")));
    assert!(gltf.nodes().all(|n| n.name() != Some("curves")));

    let bytes = halo4d::export::to_curves_ply(&none, "empty");
    let parser = ply_rs::parser::Parser::<ply_rs::ply::DefaultElement>::new();
    let ply = parser.read_ply(&mut bytes.as_slice()).unwrap();
    for element in ["vertex", "edge"] {
        assert_eq!(ply.header.elements[element].count, 0, "{element}");
        assert!(ply.payload.get(element).is_none_or(|e| e.is_empty()));
    }
    let text = String::from_utf8(bytes).unwrap();
    assert!(text.ends_with("end_header\n"), "{text}");
}

#[test]
fn a_scene_reads_back_from_its_glb_with_every_surface_and_its_halo() {
    let dir = tempfile::tempdir().unwrap();
    // Two surfaces, so that halos are matched to surfaces by `surface_mesh`, not by order.
    let scene = Scene::parse(
        r#"{ "name": "pair", "surfaces": [
             { "name": "flat", "surface": { "type": "patches", "count": 2 } },
             { "name": "torus", "surface": { "type": "flat_torus" } } ],
             "sampling": { "method": "uniform", "u": 8, "v": 8 },
             "view": { "rotation": { "yw": 40 } } }"#,
        "pair",
    )
    .unwrap();
    let built = build(&scene, dir.path());
    let bytes = std::fs::read(dir.path().join("pair.glb")).unwrap();
    let read = read_scene_glb(&bytes).unwrap();
    assert_eq!(read.name.as_deref(), Some("pair"));
    assert_eq!(read.surfaces.len(), built.surfaces.len());
    let gltf = gltf::Gltf::from_slice(&bytes).unwrap();
    for (p, s) in built.surfaces.iter().zip(&read.surfaces) {
        assert_eq!(s.name, p.name);
        assert_eq!(
            gltf.meshes().nth(s.mesh).unwrap().name(),
            Some(p.name.as_str())
        );
        // Exactly what the build worked on: it rounds to f32 at the projection.
        assert_eq!(s.positions, p.projected.positions, "{}", p.name);
        assert_eq!(s.w, p.projected.w, "{}", p.name);
        assert_eq!(s.triangles, p.mesh.triangles, "{}", p.name);

        let h = s.halo.as_ref().expect("a halo per surface");
        assert_eq!(h.name, format!("{}-halo", p.name));
        assert_eq!(h.mesh, p.halo.tet_mesh(&p.mesh.triangles), "{}", p.name);
        assert_eq!(h.mesh.surface_vertices, s.positions.len());
        assert_eq!(h.params.delta_d, Some(scene.halo.delta_d));
        assert_eq!(h.params.delta_t, Some(scene.halo.delta_t));
        assert_eq!(h.params.surface_mesh, Some(s.mesh));
        assert_eq!(h.d_orig.as_deref(), Some(&p.halo.d_orig[..]));
    }
    // The curves' exact polylines, in halo4d's frame, as the viewer draws them; gone (and
    // no error) when another program re-used their accessors.
    let c = read.curves.as_ref().expect("the curves' polylines");
    let points: Vec<_> = built
        .shown_curves()
        .curves
        .iter()
        .flat_map(|c| &c.points)
        .collect();
    let want: Vec<DVec3> = points
        .iter()
        .map(|p| p.position.as_vec3().as_dvec3())
        .collect();
    assert_eq!(c.positions, want);
    let w: Vec<f64> = points
        .iter()
        .map(|p| f64::from(p.w[p.near()] as f32))
        .collect();
    assert_eq!(c.w, w);
    assert_eq!(c.segments, expected_segments(&built.curves));
    let reused = with_json(&bytes, |j| {
        let a = j["meshes"]
            .as_array()
            .unwrap()
            .iter()
            .find(|m| m["name"] == "curves")
            .unwrap()["extras"]["curves"]["polylines"]["POSITION"]
            .as_u64()
            .unwrap() as usize;
        j["accessors"][a].as_object_mut().unwrap().remove("name");
    });
    let again = read_scene_glb(&reused).unwrap();
    assert!(again.curves.is_none());
    assert_eq!(again.surfaces, read.surfaces);
    // The curves between the two surfaces are found again, and the halos explain them.
    let (curves, v) = halo4d::verify_scene(&read);
    assert!(curves.report.count > 0 && v.curve_samples > 0, "{v:?}");
    assert!(
        curves
            .curves
            .iter()
            .flat_map(|c| &c.points)
            .any(|p| p.faces[0].surface != p.faces[1].surface),
        "no curve between the two surfaces"
    );
    assert_eq!((v.wrong, v.spurious_hidden_samples), (0, 0), "{v:?}");
    assert!(v.correct > 0, "{v:?}");
}

/// The JSON chunk and the BIN chunk's data offset of a .glb.
fn split(glb: &[u8]) -> (Value, usize) {
    let json_len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let json = serde_json::from_slice(&glb[20..20 + json_len]).unwrap();
    (json, 20 + json_len + 8)
}

/// Where in the .glb the values of attribute `attr` of the first mesh whose extras carry
/// `kind` lie, and how many there are.
fn attribute_at(glb: &[u8], kind: &str, attr: &str) -> (usize, usize) {
    let (json, bin) = split(glb);
    let mesh = json["meshes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|m| m["extras"].get(kind).is_some())
        .unwrap();
    let a =
        &json["accessors"][mesh["primitives"][0]["attributes"][attr].as_u64().unwrap() as usize];
    let view = &json["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
    let offset = view["byteOffset"].as_u64().unwrap_or(0) + a["byteOffset"].as_u64().unwrap_or(0);
    (bin + offset as usize, a["count"].as_u64().unwrap() as usize)
}

/// Applies `f` to `count` f32 values (of `components` each) at `at`.
fn edit_f32(bytes: &mut [u8], at: usize, count: usize, f: impl Fn(f32) -> f32) {
    for k in 0..count {
        let b = &mut bytes[at + 4 * k..at + 4 * k + 4];
        let x = f32::from_le_bytes(b.try_into().unwrap());
        b.copy_from_slice(&f(x).to_le_bytes());
    }
}

/// The number on the line of `halo4d check DIR`'s output that starts with `label`.
fn count(text: &str, label: &str) -> usize {
    text.lines()
        .find_map(|l| {
            let mut words = l.split_whitespace();
            (words.next() == Some(label)).then(|| words.next().unwrap().parse().unwrap())
        })
        .unwrap_or_else(|| panic!("no `{label}` in {text}"))
}

#[test]
fn check_dir_passes_a_build_and_catches_faults_planted_in_its_glb() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Scene::load(&fixture("scenes/patches.json")).unwrap();
    let built = build(&scene, &dir.path().join("patches"));
    let out = halo4d(&["check", "patches"], dir.path());
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{text}");
    for word in [
        "patches-halo",
        "quad_mismatches",
        "curve_samples",
        "correct",
        "ambiguous",
        "third_sheet",
        "surface_samples",
        "far_tetrahedra",
        "spurious_hidden_samples",
    ] {
        assert!(text.contains(word), "`{word}` not in {text}");
    }
    assert!(
        text.lines()
            .last()
            .unwrap()
            .starts_with("ok: 1 halo conforms")
    );
    assert!(!text.contains("FAILED"), "{text}");
    let (correct, third) = (count(&text, "correct"), count(&text, "third_sheet"));
    assert!(correct > 0, "{text}");
    // No halo explains any sample: each is wrong, or excused near a curve's end at the
    // boundary; most of those the build found explained are now wrong.
    let explains_nothing = |text: &str| {
        assert_eq!((count(text, "correct"), count(text, "third_sheet")), (0, 0));
        let (wrong, ambiguous) = (count(text, "wrong"), count(text, "ambiguous"));
        assert_eq!(wrong + ambiguous, count(text, "curve_samples"), "{text}");
        assert!(2 * wrong > correct + third, "{text}");
    };
    assert_eq!(
        (
            count(&text, "wrong"),
            count(&text, "spurious_hidden_samples")
        ),
        (0, 0)
    );
    // The build verified the same halo against its own (f64) curves.
    assert_eq!(built.verification.wrong, 0);

    let glb = std::fs::read(dir.path().join("patches/patches.glb")).unwrap();
    let imported: ImportedScene = read_scene_glb(&glb).unwrap();
    let w = imported.surfaces.iter().flat_map(|s| s.w.iter().copied());
    let (lo, hi) = w.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
        (lo.min(x), hi.max(x))
    });
    let planted = |name: &str, bytes: &[u8]| {
        let d = dir.path().join(name);
        std::fs::create_dir(&d).unwrap();
        std::fs::write(d.join("patches.glb"), bytes).unwrap();
        let out = halo4d(&["check", name], dir.path());
        let text = String::from_utf8_lossy(&out.stdout).into_owned();
        assert_eq!(out.status.code(), Some(1), "{name}: {text}");
        // The tetrahedra are as good as before: only the verification fails.
        assert!(!text.contains("FAILED patches-halo"), "{name}: {text}");
        text
    };

    // The halo mesh no longer marked as one: a scene without halos, whose curves nothing
    // explains.
    let text = planted(
        "bare",
        &with_json(&glb, |j| {
            for m in j["meshes"].as_array_mut().unwrap() {
                m["extras"].as_object_mut().unwrap().remove("halo");
            }
        }),
    );
    assert!(text.contains("no halo in the file"), "{text}");
    explains_nothing(&text);

    // d_orig of every halo vertex raised by more than the whole scene's range of w. A halo
    // depth (eq. 3) is d_orig interpolated plus a non-negative term, and d_orig is at least
    // the smallest w, so every halo depth now exceeds every sheet's w: no halo hides anything.
    // Each curve sample must then be wrong or excused, whatever the geometry: the test cannot
    // pass by accident.
    let mut raised = glb.clone();
    let (at, n) = attribute_at(&glb, "halo", "_D");
    let lift = (2.0 * (hi - lo) + 1.0) as f32;
    edit_f32(&mut raised, at, n, |d| d + lift);
    let text = planted("raised", &raised);
    explains_nothing(&text);
    assert!(
        text.contains("FAILED halo verification") && text.contains("curve samples wrong"),
        "{text}"
    );

    // The halo's positions doubled (about the origin: exact in f32, a similarity, so the
    // checker sees the same valid tetrahedra): the halo now hides the sheets far from the
    // surface it was built over, which only a spurious gap explains.
    let mut doubled = glb.clone();
    let (at, n) = attribute_at(&glb, "halo", "POSITION");
    edit_f32(&mut doubled, at, 3 * n, |x| 2.0 * x);
    let text = planted("doubled", &doubled);
    assert!(count(&text, "spurious_hidden_samples") > 0, "{text}");
    assert!(
        text.contains("FAILED halo verification") && text.contains("spuriously hidden"),
        "{text}"
    );
}

#[test]
fn check_dir_on_an_unreadable_folder_is_an_error_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Scene::load(&fixture("scenes/patches.json")).unwrap();
    build(&scene, &dir.path().join("patches"));
    let glb = std::fs::read(dir.path().join("patches/patches.glb")).unwrap();
    let folder = |name: &str, files: &[(&str, &[u8])]| {
        let d = dir.path().join(name);
        std::fs::create_dir(&d).unwrap();
        for (f, bytes) in files {
            std::fs::write(d.join(f), bytes).unwrap();
        }
    };
    folder("cut", &[("patches.glb", &glb[..glb.len() / 2])]);
    folder("none", &[("notes.txt", b"hello")]);
    folder("two", &[("a.glb", &glb), ("b.glb", &glb)]);
    let no_halo_surface = with_json(&glb, |j| {
        for m in j["meshes"].as_array_mut().unwrap() {
            m["extras"].as_object_mut().unwrap().remove("surface");
        }
    });
    folder("bare", &[("patches.glb", &no_halo_surface)]);
    for (name, words) in [
        ("cut", &["cut", "patches.glb", "truncated"][..]),
        ("none", &["none", "no .glb"]),
        ("two", &["two", "2 .glb files", "a.glb, b.glb"]),
        ("bare", &["patches.glb", "no surface"]),
    ] {
        let out = halo4d(&["check", name], dir.path());
        assert_unreadable(&out, name, words);
    }
}

/// `read_scene_glb` fails with an error containing `words`.
fn scene_fails(bytes: &[u8], words: &[&str]) {
    let e = read_scene_glb(bytes)
        .expect_err("accepted a broken scene .glb")
        .to_string();
    for w in words {
        assert!(e.contains(w), "`{w}` not in: {e}");
    }
}

#[test]
fn malformed_scene_glb_files_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Scene::load(&fixture("scenes/patches.json")).unwrap();
    let built = build(&scene, dir.path());
    let good = std::fs::read(dir.path().join("patches.glb")).unwrap();
    let n = built.surfaces[0].projected.positions.len();
    assert_eq!(read_scene_glb(&good).unwrap().surfaces.len(), 1);

    scene_fails(&good[..100], &["truncated"]);
    let halo = |j: &mut Value| -> usize {
        j["meshes"]
            .as_array()
            .unwrap()
            .iter()
            .position(|m| m["extras"].get("halo").is_some())
            .unwrap()
    };
    let edited = |edit: &dyn Fn(&mut Value)| with_json(&good, |j| edit(j));
    scene_fails(
        &edited(&|j| {
            let h = halo(j);
            j["meshes"][h]["extras"]["halo"]["surface_mesh"] = (h as u64).into();
        }),
        &["patches-halo", "is not one of the file's surface meshes"],
    );
    scene_fails(
        &edited(&|j| {
            let h = halo(j);
            j["meshes"][h]["extras"]["halo"]
                .as_object_mut()
                .unwrap()
                .remove("surface_mesh");
        }),
        &["no `surface_mesh`"],
    );
    scene_fails(
        &edited(&|j| {
            let h = halo(j);
            j["meshes"][h]["extras"]["halo"]["surface_vertices"] = (n - 1).into();
        }),
        &[
            &format!("surface_vertices = {}", n - 1),
            &format!("{n} vertices"),
        ],
    );
    scene_fails(
        &edited(&|j| {
            let h = halo(j);
            j["meshes"][h]["extras"]["halo"]
                .as_object_mut()
                .unwrap()
                .remove("delta_t");
        }),
        &["patches-halo", "delta_t"],
    );
    scene_fails(
        &edited(&|j| {
            let h = halo(j);
            let copy = j["meshes"][h].clone();
            j["meshes"].as_array_mut().unwrap().push(copy);
        }),
        &["has a halo already"],
    );
    scene_fails(
        &edited(&|j| {
            let w = j["meshes"][0]["primitives"][0]["attributes"]["_W"]
                .as_u64()
                .unwrap() as usize;
            j["accessors"][w]["count"] = 5.into();
        }),
        &[
            "surface `patches`",
            &format!("_W has 5 values for {n} positions"),
        ],
    );
    scene_fails(
        &edited(&|j| j["meshes"][0]["primitives"][0]["mode"] = 1.into()),
        &["mode 1", "TRIANGLES"],
    );
    scene_fails(
        &edited(&|j| {
            j["meshes"][0]["primitives"][0]["attributes"]
                .as_object_mut()
                .unwrap()
                .remove("_W");
        }),
        &["no `_W`"],
    );
    // Values in the binary chunk: a triangle that repeats a vertex, an index out of range.
    let (json, bin) = split(&good);
    let indices = &json["accessors"][json["meshes"][0]["primitives"][0]["indices"]
        .as_u64()
        .unwrap() as usize];
    let view = &json["bufferViews"][indices["bufferView"].as_u64().unwrap() as usize];
    let at = bin + view["byteOffset"].as_u64().unwrap_or(0) as usize;
    let mut repeated = good.clone();
    let first: [u8; 4] = repeated[at..at + 4].try_into().unwrap();
    repeated[at + 4..at + 8].copy_from_slice(&first);
    scene_fails(
        &repeated,
        &["surface `patches`", "triangle 0 repeats a vertex"],
    );
    let mut beyond = good.clone();
    beyond[at..at + 4].copy_from_slice(&9_000_000u32.to_le_bytes());
    scene_fails(&beyond, &["triangle 0 names vertex 9000000"]);
    let (w_at, _) = attribute_at(&good, "surface", "_W");
    let mut nan = good.clone();
    nan[w_at + 8..w_at + 12].copy_from_slice(&f32::INFINITY.to_le_bytes());
    scene_fails(&nan, &["_W of vertex 2 is not finite"]);
    assert!(matches!(
        read_scene_glb(&edited(&|j| {
            j["meshes"][0]["extras"]
                .as_object_mut()
                .unwrap()
                .remove("surface");
        })),
        Err(ImportError::NoSurface(_))
    ));
}

#[test]
fn no_cut_or_corrupted_scene_glb_panics_the_reader_or_the_verification() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Scene::load(&fixture("scenes/patches.json")).unwrap();
    build(&scene, dir.path());
    let good = std::fs::read(dir.path().join("patches.glb")).unwrap();
    for cut in (0..good.len()).step_by(good.len() / 200) {
        assert!(read_scene_glb(&good[..cut]).is_err(), "cut at {cut}");
    }
    let mut rng = Rng(0xc0e5);
    let mut verified = 0;
    for _ in 0..120 {
        let mut bytes = good.clone();
        for _ in 0..1 + rng.below(4) {
            let at = rng.below(bytes.len());
            bytes[at] = rng.bits() as u8;
        }
        // Whatever a corrupted file still reads as is verified without a panic.
        if let Ok(s) = read_scene_glb(&bytes) {
            let _ = halo4d::verify_scene(&s);
            verified += 1;
        }
    }
    assert!(verified > 0);
}
