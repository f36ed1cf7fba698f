//! Export round trips through real readers: gltf for .glb, ply-rs for .ply, tobj for .obj.

use crate::common::{fixture_scenes, hard_scenes};
use halo4d::Scene;
use ply_rs::ply::Property;

fn float(p: &Property) -> f64 {
    match p {
        Property::Float(x) => f64::from(*x),
        Property::Int(x) => f64::from(*x),
        other => panic!("unexpected property {other:?}"),
    }
}

#[test]
fn every_fixture_builds_and_reads_back() {
    let dir = tempfile::tempdir().unwrap();
    for path in fixture_scenes().into_iter().chain(hard_scenes()) {
        let mut scene = Scene::load(&path).unwrap();
        scene.outputs.obj = true;
        // The picture's own tests look at it; here it only has to be written.
        (
            scene.render.width,
            scene.render.height,
            scene.render.samples,
        ) = (128, 128, 1);
        let out = dir.path().join(&scene.name);
        let built = crate::common::built(&scene).unwrap();
        let products = &built.surfaces;
        let report = halo4d::write(&scene, &built, &out)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let name = &scene.name;

        // Every halo is valid, as the independent checker sees it: conforming, no inverted
        // or flat tetrahedron, the volumes adding up.
        for p in products {
            let c = p.halo_report.check;
            let what = format!("{name}/{}: {c:?}", p.name);
            assert!(c.passes(), "{what}");
            assert_eq!(p.halo_report.inverted, 0, "{what}");
            assert_eq!(p.halo_report.split_stats.mismatches_final, 0, "{what}");
            // Three per layer of a prism, one fewer in each layer for each collapsed corner
            // (rho 0), five more for each inserted vertex.
            let collapsed_corners = p
                .mesh
                .triangles
                .iter()
                .flatten()
                .filter(|&&v| p.halo.rho[v as usize] == 0.0)
                .count();
            assert_eq!(
                c.tets + 2 * collapsed_corners,
                6 * p.mesh.triangles.len() + 5 * p.halo_report.split_stats.inserted_vertices,
                "{what}"
            );
        }

        // glTF: one mesh per surface, named after it, with the custom attributes, one per
        // halo (tests/halo_export.rs reads those), one of the curves, if any
        // (tests/curves_export.rs reads that), and one of the stipples where the scene asks
        // (tests/stipple.rs reads that).
        let glb = std::fs::read(out.join(format!("{name}.glb"))).unwrap();
        let gltf = gltf::Gltf::from_slice(&glb).unwrap_or_else(|e| panic!("{name}.glb: {e}"));
        let blob = gltf.blob.as_deref().expect("binary chunk");
        assert_eq!(
            gltf.meshes().count(),
            2 * products.len()
                + usize::from(!built.curves.curves.is_empty())
                + usize::from(scene.outputs.stipples)
        );
        let extras = gltf
            .document
            .as_json()
            .asset
            .extras
            .as_ref()
            .expect("asset extras");
        let recorded: serde_json::Value = serde_json::from_str(extras.get()).unwrap();
        assert_eq!(
            recorded["halo4d"]["scene"],
            serde_json::to_value(&scene).unwrap()
        );
        for p in products {
            let mesh = gltf
                .meshes()
                .find(|m| m.name() == Some(p.name.as_str()))
                .unwrap_or_else(|| panic!("{name}.glb: no mesh `{}`", p.name));
            let prim = mesh.primitives().next().unwrap();
            assert_eq!(prim.mode(), gltf::mesh::Mode::Triangles);
            let reader = prim.reader(|_| Some(blob));
            let positions: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
            assert_eq!(positions.len(), p.mesh.vertex_count());
            let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
            assert_eq!(indices.len(), 3 * p.mesh.triangles.len());
            assert!(indices.iter().all(|i| (*i as usize) < positions.len()));
            for n in reader.read_normals().unwrap() {
                let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                assert!((len - 1.0).abs() < 1e-5);
            }
            // POSITION min/max are exactly the extremes of the stored f32 values.
            let acc = prim.get(&gltf::Semantic::Positions).unwrap();
            let min: Vec<f32> = serde_json::from_value(acc.min().unwrap()).unwrap();
            for k in 0..3 {
                let lo = positions.iter().map(|q| q[k]).fold(f32::INFINITY, f32::min);
                assert_eq!(min[k], lo);
            }
            for (attr, expect) in [
                ("_W", p.projected.w.clone()),
                ("_U", p.mesh.uv.iter().map(|x| x[0]).collect()),
                ("_V", p.mesh.uv.iter().map(|x| x[1]).collect()),
                (
                    "_PATCH",
                    p.mesh.patch.iter().map(|x| f64::from(*x)).collect(),
                ),
            ] {
                let acc = prim
                    .attributes()
                    .find(|(s, _)| s.to_string() == attr)
                    .unwrap_or_else(|| panic!("{name}: no {attr}"))
                    .1;
                assert_eq!(acc.data_type(), gltf::accessor::DataType::F32);
                assert_eq!(acc.dimensions(), gltf::accessor::Dimensions::Scalar);
                let view = acc.view().unwrap();
                let bytes = &blob[view.offset() + acc.offset()..][..acc.count() * 4];
                for (chunk, e) in bytes.chunks_exact(4).zip(&expect) {
                    let got = f32::from_le_bytes(chunk.try_into().unwrap());
                    assert_eq!(got, *e as f32, "{name}: {attr}");
                }
            }
        }

        // PLY: same vertex and face counts, w as quality.
        let ply_bytes = std::fs::read(out.join(format!("{name}.ply"))).unwrap();
        let parser = ply_rs::parser::Parser::<ply_rs::ply::DefaultElement>::new();
        let ply = parser.read_ply(&mut ply_bytes.as_slice()).unwrap();
        let vertices = &ply.payload["vertex"];
        let faces = &ply.payload["face"];
        assert_eq!(
            vertices.len(),
            products
                .iter()
                .map(|p| p.mesh.vertex_count())
                .sum::<usize>()
        );
        assert_eq!(
            faces.len(),
            products
                .iter()
                .map(|p| p.mesh.triangles.len())
                .sum::<usize>()
        );
        let w: Vec<f64> = products
            .iter()
            .flat_map(|p| p.projected.w.iter().copied())
            .collect();
        for (v, w) in vertices.iter().zip(&w) {
            assert_eq!(float(&v["quality"]), f64::from(*w as f32));
        }

        // OBJ through tobj: one model per surface with the same counts.
        let (models, _) =
            tobj::load_obj(out.join(format!("{name}.obj")), &tobj::GPU_LOAD_OPTIONS).unwrap();
        assert_eq!(models.len(), products.len());
        for (m, p) in models.iter().zip(products) {
            assert_eq!(m.name, p.name);
            assert_eq!(m.mesh.indices.len(), 3 * p.mesh.triangles.len());
            assert_eq!(m.mesh.positions.len(), 3 * p.mesh.vertex_count());
        }

        // The report lists what was written and counts what was built.
        let text = std::fs::read_to_string(out.join("report.json")).unwrap();
        let json: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(json["surfaces"].as_array().unwrap().len(), products.len());
        assert_eq!(
            json["surfaces"][0]["triangles"],
            products[0].mesh.triangles.len()
        );
        // .glb, .ply, -curves.ply, .obj, .png, report.json, a .vtk per halo, and
        // -stipples.ply and .svg where the scene asks.
        assert_eq!(
            report.files.len(),
            6 + products.len()
                + usize::from(scene.outputs.stipples)
                + usize::from(scene.outputs.svg)
        );
        assert!(
            !text.contains("NaN") && !text.contains("null,"),
            "report has a non-number"
        );
        let files: Vec<_> = std::fs::read_dir(&out).unwrap().collect();
        assert_eq!(files.len(), report.files.len(), "{name}: {files:?}");
        for file in files {
            assert_only_finite_numbers(&file.unwrap().path());
        }
    }
}

/// Fails unless every number `path` stores is finite: each float of a .glb's accessors (and
/// their bounds), of a .ply's elements and of a .vtk's points and data, each number of a
/// .json (serde_json writes a non-finite one as null: only fields documented as optional
/// may be null) and each coordinate of an .obj.
fn assert_only_finite_numbers(path: &std::path::Path) {
    let what = path.display();
    let bytes = std::fs::read(path).unwrap();
    let finite = |x: f64, at: &str| assert!(x.is_finite(), "{what}: {x} in {at}");
    match path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or_default()
    {
        "glb" => {
            let gltf = gltf::Gltf::from_slice(&bytes).unwrap();
            let blob = gltf.blob.as_deref().unwrap();
            for a in gltf.accessors() {
                let at = a.name().unwrap_or("an accessor").to_string();
                for bound in [a.min(), a.max()] {
                    let bound = bound.map(|b| serde_json::to_string(&b).unwrap());
                    assert!(bound.is_none_or(|b| !b.contains("null")), "{what}: {at}");
                }
                if a.data_type() != gltf::accessor::DataType::F32 {
                    continue;
                }
                let view = a.view().unwrap();
                let start = view.offset() + a.offset();
                let len = a.count() * a.dimensions().multiplicity() * 4;
                for c in blob[start..start + len].chunks_exact(4) {
                    finite(f64::from(f32::from_le_bytes(c.try_into().unwrap())), &at);
                }
            }
        }
        "ply" => {
            let parser = ply_rs::parser::Parser::<ply_rs::ply::DefaultElement>::new();
            let ply = parser.read_ply(&mut bytes.as_slice()).unwrap();
            for (element, rows) in &ply.payload {
                for row in rows {
                    for (key, p) in row {
                        if let Property::Float(x) = p {
                            finite(f64::from(*x), &format!("{element}.{key}"));
                        }
                    }
                }
            }
        }
        "vtk" => {
            let halo = halo4d::import::read_vtk(&bytes).unwrap();
            for p in &halo.mesh.positions {
                p.iter().for_each(|&x| finite(x, "POINTS"));
            }
            for (field, values) in [("t", &halo.t), ("d_orig", &halo.d_orig)] {
                let values = values.as_ref().expect("the halo's point data");
                values.iter().for_each(|&x| finite(x, field));
            }
        }
        "json" => {
            fn walk(v: &serde_json::Value, at: &str, what: &str) {
                match v {
                    serde_json::Value::Null => assert!(
                        at.ends_with("euler_characteristic"),
                        "{what}: null (a non-finite number?) at {at}"
                    ),
                    serde_json::Value::Array(a) => {
                        for (i, x) in a.iter().enumerate() {
                            walk(x, &format!("{at}[{i}]"), what);
                        }
                    }
                    serde_json::Value::Object(o) => {
                        for (k, x) in o {
                            walk(x, &format!("{at}.{k}"), what);
                        }
                    }
                    _ => {}
                }
            }
            walk(
                &serde_json::from_slice(&bytes).unwrap(),
                "",
                &what.to_string(),
            );
        }
        "obj" => {
            let text = String::from_utf8(bytes).unwrap();
            for line in text.lines().filter(|l| l.starts_with("v ")) {
                for x in line.split_whitespace().skip(1) {
                    finite(x.parse().unwrap(), line);
                }
            }
        }
        "svg" => {
            // Every number of the line art finite (the paths' points and widths).
            let text = String::from_utf8(bytes).unwrap();
            assert!(
                text.contains("<svg") && text.trim_end().ends_with("</svg>"),
                "{what}"
            );
            let numbers = text
                .split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-'))
                .filter_map(|t| t.parse::<f64>().ok());
            for x in numbers {
                finite(x, "a path");
            }
            assert!(!text.contains("NaN") && !text.contains("inf"), "{what}");
        }
        "png" | "mtl" => {}
        other => panic!("{what}: a file of unknown kind {other:?}"),
    }
}

#[test]
fn an_unwritable_output_folder_is_a_clear_error_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Scene::default_scene();
    // The output "folder" is a file: the build must fail with a clear error.
    let blocker = dir.path().join("occupied");
    std::fs::write(&blocker, b"x").unwrap();
    let err = halo4d::build(&scene, &blocker, halo4d::progress::Job::SILENT)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("cannot write") && err.contains("--out"),
        "{err}"
    );
    let leftovers: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(leftovers.len(), 1);
}

#[test]
fn check_dir_finds_the_build_s_verification_and_the_mesh_s_curve_points() {
    // The Klein bottle's refinement trims a point beyond a cross-cap: `check DIR`, which
    // recomputes the mesh's curves from the file, counts it.
    let scene = halo4d::Scene::load(&crate::common::fixture("scenes/klein-bottle.json")).unwrap();
    let built = crate::common::built(&scene).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let report = halo4d::write(&scene, &built, dir.path()).unwrap();
    let checked = halo4d::check_dir(dir.path()).unwrap();
    assert!(checked.failures().is_empty());
    let (curves, verification) = checked.verification.expect("a folder is verified");
    let built_curves = report.curves.expect("the build found curves");
    let trimmed = built_curves.refinement.as_ref().map_or(0, |r| r.trimmed);
    assert!(trimmed > 0, "the fixture trims a point: {built_curves:?}");
    assert_eq!(curves.points, built_curves.points + trimmed);
    assert_eq!(curves.count, built_curves.count);
    assert_eq!(
        curves.points, built.curves.report.points,
        "the mesh's curves"
    );
    let v = report.halo_verification.expect("verified");
    assert_eq!(
        (
            verification.curve_samples,
            verification.correct,
            verification.wrong
        ),
        (v.curve_samples, v.correct, v.wrong)
    );
}
