//! Halos through their files: every fixture's halo written to .glb and .vtk and read back
//! (by halo4d's readers and by the gltf crate) unchanged; faults planted in the files caught
//! by `halo4d check`; malformed files rejected with errors, never panics.

use crate::common::{
    Rng, assert_unreadable, failure_names, fixture, fixture_scenes, halo4d, with_json,
};
use glam::{DVec3, Vec3};
use halo4d::Scene;
use halo4d::SurfaceProduct;
use halo4d::check::check;
use halo4d::import::FileTetrahedra;
use halo4d::internals::file_order;
use halo4d::{import::ImportError, import::ImportedHalo, import::read_glb, import::read_vtk};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// Builds a scene into `dir`, returning its products.
fn build(scene: &Scene, dir: &Path) -> Vec<SurfaceProduct> {
    let built = crate::common::built(scene).unwrap();
    halo4d::write(scene, &built, dir).unwrap();
    built.surfaces
}

/// The patches fixture (whose halo is valid) built into `dir`: its .glb and .vtk.
fn patches(dir: &Path) -> (PathBuf, PathBuf, Vec<SurfaceProduct>) {
    let scene = Scene::load(&fixture("scenes/patches.json")).unwrap();
    let products = build(&scene, dir);
    (
        dir.join("patches.glb"),
        dir.join("patches-halo.vtk"),
        products,
    )
}

fn bits(values: &[f64]) -> Vec<u64> {
    values.iter().map(|x| x.to_bits()).collect()
}

fn bits3(values: &[[f64; 3]]) -> Vec<u64> {
    values.iter().flatten().map(|x| x.to_bits()).collect()
}

fn f32_bits(values: &[f64]) -> Vec<u64> {
    values
        .iter()
        .map(|&x| f64::from(x as f32).to_bits())
        .collect()
}

/// The halos of a file halo4d wrote, read as `halo4d check` reads them.
fn read_halos(path: &Path) -> Result<Vec<ImportedHalo>, ImportError> {
    match halo4d::import::read(path)? {
        FileTetrahedra::Halos(halos) => Ok(halos),
        FileTetrahedra::Plain(mesh) => {
            panic!("{}: not read as halos: {}", path.display(), mesh.why)
        }
    }
}

/// An ASCII legacy VTK of `h`; `with_layout`: with halo4d's FIELD data right after DATASET
/// (where VTK's own writer puts it, not where halo4d does), else with none, as another
/// program writes it.
fn ascii_vtk(h: &ImportedHalo, with_layout: bool) -> String {
    let m = &h.mesh;
    let mut s = format!(
        "# vtk DataFile Version 3.0\n{}: ascii copy\nASCII\nDATASET UNSTRUCTURED_GRID\n",
        h.name
    );
    if with_layout {
        let triangles = &m.surface_triangles;
        s += &format!(
            "FIELD FieldData 4\nsurface_vertices 1 1 int\n{}\nlayers 1 1 int\n2\nrho 1 1 double\n{}\nsurface_triangles 3 {} int\n",
            m.surface_vertices,
            h.params.rho.unwrap(),
            triangles.len()
        );
        for t in triangles {
            s += &format!("{} {} {}\n", t[0], t[1], t[2]);
        }
    }
    s += &format!("POINTS {} double\n", m.positions.len());
    for p in &m.positions {
        s += &format!("{} {} {}\n", p[0], p[1], p[2]);
    }
    s += &format!("CELLS {} {}\n", m.tets.len(), 5 * m.tets.len());
    for &t in &m.tets {
        let t = file_order(t);
        s += &format!("4 {} {} {} {}\n", t[0], t[1], t[2], t[3]);
    }
    s += &format!("CELL_TYPES {}\n", m.tets.len());
    s += &"10\n".repeat(m.tets.len());
    s += &format!("POINT_DATA {}\n", m.positions.len());
    for (name, values) in [("t", &h.t), ("d_orig", &h.d_orig)] {
        s += &format!("SCALARS {name} double\nLOOKUP_TABLE default\n");
        for x in values.as_ref().unwrap() {
            s += &format!("{x}\n");
        }
    }
    s
}

/// Where the BIN chunk's data starts in a .glb.
fn bin_start(glb: &[u8]) -> usize {
    let json_len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    20 + json_len + 8
}

/// The JSON of the first halo mesh and its index.
fn halo_mesh(json: &mut Value) -> &mut Value {
    json["meshes"]
        .as_array_mut()
        .unwrap()
        .iter_mut()
        .find(|m| m["extras"].get("halo").is_some())
        .unwrap()
}

/// Where in the .glb the first halo's tetrahedra and positions lie.
fn halo_offsets(glb: &[u8]) -> (usize, usize) {
    let gltf = gltf::Gltf::from_slice(glb).unwrap();
    let mesh = gltf
        .meshes()
        .find(|m| m.name().is_some_and(|n| n.ends_with("-halo")))
        .unwrap();
    let extras: Value = serde_json::from_str(mesh.extras().as_ref().unwrap().get()).unwrap();
    let at = |a: gltf::Accessor| bin_start(glb) + a.view().unwrap().offset() + a.offset();
    let tets = gltf
        .accessors()
        .nth(extras["halo"]["tetrahedra"].as_u64().unwrap() as usize)
        .unwrap();
    let positions = mesh
        .primitives()
        .next()
        .unwrap()
        .get(&gltf::Semantic::Positions)
        .unwrap();
    (at(tets), at(positions))
}

#[test]
fn every_fixture_halo_reads_back_unchanged_from_glb_and_vtk() {
    let dir = tempfile::tempdir().unwrap();
    for path in fixture_scenes() {
        let scene = Scene::load(&path).unwrap();
        let out = dir.path().join(&scene.name);
        let products = build(&scene, &out);
        let name = &scene.name;
        let from_glb = read_halos(&out.join(format!("{name}.glb"))).unwrap();
        assert_eq!(from_glb.len(), products.len(), "{name}");
        for (p, g) in products.iter().zip(&from_glb) {
            let halo = &p.halo;
            let what = format!("{name}/{}", p.name);
            let mesh = halo.tet_mesh(&p.mesh.triangles);
            let vtk_file = if products.len() == 1 {
                format!("{name}-halo.vtk")
            } else {
                format!("{name}-{}-halo.vtk", p.name)
            };
            let v = read_vtk(&std::fs::read(out.join(vtk_file)).unwrap()).unwrap();
            let expected = check(&mesh);
            for h in [g, &v] {
                assert_eq!(h.name, format!("{}-halo", p.name), "{what}");
                assert_eq!(h.mesh.surface_vertices, halo.surface_vertices, "{what}");
                assert_eq!(h.mesh.tets, halo.tets, "{what}");
                assert_eq!(h.params.rho, Some(p.halo_report.rho), "{what}");
                assert_eq!(h.params.delta_d, Some(scene.halo.delta_d), "{what}");
                assert_eq!(h.params.delta_t, Some(scene.halo.delta_t), "{what}");
            }
            // The .glb: f32, and the halo's positions are exact in f32, so bit for bit.
            assert_eq!(bits3(&g.mesh.positions), bits3(&mesh.positions), "{what}");
            assert_eq!(bits(g.t.as_ref().unwrap()), f32_bits(&halo.t), "{what}");
            assert_eq!(bits(g.d_orig.as_ref().unwrap()), f32_bits(&halo.d_orig));
            assert_eq!(g.params.split.as_deref(), Some(scene.halo.split.name()));
            // The checker sees in the files exactly what it saw in memory.
            assert_eq!(check(&g.mesh), expected, "{what}");
            // The .vtk: f64, bit for bit.
            assert_eq!(bits3(&v.mesh.positions), bits3(&mesh.positions), "{what}");
            assert_eq!(bits(v.t.as_ref().unwrap()), bits(&halo.t), "{what}");
            assert_eq!(
                bits(v.d_orig.as_ref().unwrap()),
                bits(&halo.d_orig),
                "{what}"
            );
            assert_eq!(check(&v.mesh), expected, "{what}");
            // An ASCII copy reads back bit for bit too (Rust prints f64 so that it parses
            // back exactly).
            let a = read_vtk(ascii_vtk(&v, true).as_bytes()).unwrap();
            assert_eq!(bits3(&a.mesh.positions), bits3(&mesh.positions), "{what}");
            assert_eq!(a.mesh, v.mesh, "{what}");
            assert_eq!((&a.t, &a.d_orig), (&v.t, &v.d_orig), "{what}");
        }
    }
}

#[test]
fn the_glb_halo_is_plain_gltf_to_the_gltf_crate() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Scene::default_scene();
    let products = build(&scene, dir.path());
    let glb = std::fs::read(dir.path().join(format!("{}.glb", scene.name))).unwrap();
    let gltf = gltf::Gltf::from_slice(&glb).unwrap();
    let blob = gltf.blob.as_deref().unwrap();
    for p in &products {
        let halo = &p.halo;
        let n = halo.surface_vertices;
        let mesh = gltf
            .meshes()
            .find(|m| m.name() == Some(format!("{}-halo", p.name).as_str()))
            .expect("a halo mesh per surface");
        assert!(
            gltf.nodes()
                .any(|node| node.mesh().map(|m| m.index()) == Some(mesh.index())),
            "the halo mesh has its own node"
        );
        let prim = mesh.primitives().next().unwrap();
        assert_eq!(prim.mode(), gltf::mesh::Mode::Triangles);
        let reader = prim.reader(|_| Some(blob));
        // glTF's frame, y up: (x, y, z) of halo4d is (x, z, -y), and exact in f32.
        let positions: Vec<DVec3> = reader
            .read_positions()
            .unwrap()
            .map(|p| Vec3::from(p).as_dvec3())
            .collect();
        let expected: Vec<DVec3> = halo
            .positions
            .iter()
            .map(|p| DVec3::new(p.x, p.z, -p.y))
            .collect();
        assert_eq!(positions, expected);
        // Unit normals, turned out of the halo (along the offset from the surface).
        let normals: Vec<DVec3> = reader
            .read_normals()
            .expect("NORMAL on the halo")
            .map(|p| Vec3::from(p).as_dvec3())
            .collect();
        assert_eq!(normals.len(), positions.len());
        assert!(normals.iter().all(|v| (v.length() - 1.0).abs() < 1e-6));
        let outward = (0..2 * n)
            .filter(|&i| {
                let away = positions[i] - positions[(i + n) % (2 * n)];
                away.length() == 0.0 || normals[i].dot(away) > 0.0
            })
            .count();
        assert!(
            outward as f64 >= 0.99 * (2 * n) as f64,
            "{outward} of {}",
            2 * n
        );
        let patch: Vec<f64> = (0..halo.positions.len())
            .map(|i| {
                f64::from(if i < 3 * n {
                    p.mesh.patch[i % n]
                } else {
                    p.mesh.triangle_patch[halo.inserted_in[i - 3 * n] as usize]
                })
            })
            .collect();
        for (attr, expect) in [("_T", &halo.t), ("_D", &halo.d_orig), ("_PATCH", &patch)] {
            let acc = prim
                .attributes()
                .find(|(s, _)| s.to_string() == attr)
                .unwrap_or_else(|| panic!("no {attr}"))
                .1;
            assert_eq!(acc.data_type(), gltf::accessor::DataType::F32);
            assert_eq!(acc.dimensions(), gltf::accessor::Dimensions::Scalar);
            let bytes = &blob[acc.view().unwrap().offset() + acc.offset()..][..acc.count() * 4];
            let got: Vec<f64> = bytes
                .chunks_exact(4)
                .map(|c| f64::from(f32::from_le_bytes(c.try_into().unwrap())))
                .collect();
            assert_eq!(bits(&got), f32_bits(expect), "{attr}");
        }

        // The triangles are the boundary faces, turned outward: as many as the checker
        // counts, enclosing the volume it measures, and using every offset vertex (a
        // collapsed one's second index too), so that an importer that drops unused vertices
        // keeps them all at their indices.
        let faces: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
        let stats = check(&halo.tet_mesh(&p.mesh.triangles));
        assert_eq!(faces.len(), 3 * stats.boundary_faces);
        let mut enclosed = 0.0;
        for f in faces.chunks_exact(3) {
            let [a, b, c] = [f[0], f[1], f[2]].map(|i| positions[i as usize]);
            enclosed += a.dot(b.cross(c)) / 6.0;
        }
        let mut used = vec![false; positions.len()];
        faces.iter().for_each(|&i| used[i as usize] = true);
        assert!(
            used[..2 * n].iter().all(|&u| u),
            "an offset vertex on no triangle"
        );
        assert!(
            (enclosed - stats.boundary_volume).abs() <= 1e-9 * stats.boundary_volume.abs(),
            "{enclosed} against {}",
            stats.boundary_volume
        );

        // The extras name the tetrahedra's accessor: 4 indices per tetrahedron, in a view
        // without a target.
        let extras: Value = serde_json::from_str(mesh.extras().as_ref().unwrap().get()).unwrap();
        let h = &extras["halo"];
        assert_eq!(h["surface_vertices"], n);
        assert_eq!(h["layers"], 2);
        assert_eq!(h["rho"], p.halo_report.rho);
        assert_eq!(h["split"], scene.halo.split.name());
        let surface_mesh = gltf
            .meshes()
            .nth(h["surface_mesh"].as_u64().unwrap() as usize)
            .unwrap();
        assert_eq!(surface_mesh.name(), Some(p.name.as_str()));
        let tets = gltf
            .accessors()
            .nth(h["tetrahedra"].as_u64().unwrap() as usize)
            .unwrap();
        assert_eq!(tets.count(), 4 * halo.tets.len());
        assert_eq!(tets.data_type(), gltf::accessor::DataType::U32);
        assert_eq!(tets.dimensions(), gltf::accessor::Dimensions::Scalar);
        let view = tets.view().unwrap();
        assert_eq!(view.target(), None);
        let indices: Vec<u32> = blob[view.offset() + tets.offset()..][..tets.count() * 4]
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        let file: Vec<u32> = halo.tets.iter().flat_map(|&t| file_order(t)).collect();
        assert_eq!(indices, file);
        // In the file, every tetrahedron is positive as VTK counts: det[b-a, c-a, d-a] > 0.
        for t in indices.chunks_exact(4) {
            let [a, b, c, d] = [t[0], t[1], t[2], t[3]].map(|i| positions[i as usize]);
            assert!((b - a).cross(c - a).dot(d - a) > 0.0, "{t:?}");
        }
    }
}

#[test]
fn a_scene_of_several_surfaces_writes_a_vtk_per_halo_and_checks_each() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Scene::parse(
        r#"{ "name": "pair", "surfaces": [
             { "name": "flat", "surface": { "type": "patches", "count": 2 } },
             { "name": "torus", "surface": { "type": "flat_torus" } } ],
             "sampling": { "method": "uniform", "u": 8, "v": 8 },
             "outputs": { "ply": false, "report": false } }"#,
        "pair",
    )
    .unwrap();
    let products = build(&scene, dir.path());
    let mut files: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    files.sort();
    assert_eq!(
        files,
        [
            "pair-flat-halo.vtk",
            "pair-torus-halo.vtk",
            "pair.glb",
            "pair.png"
        ]
    );
    let from_glb = read_halos(&dir.path().join("pair.glb")).unwrap();
    let names: Vec<&str> = from_glb.iter().map(|h| h.name.as_str()).collect();
    assert_eq!(names, ["flat-halo", "torus-halo"]);
    for (p, g) in products.iter().zip(&from_glb) {
        let v = read_halos(&dir.path().join(format!("pair-{}-halo.vtk", p.name))).unwrap();
        assert_eq!(v[0].mesh, p.halo.tet_mesh(&p.mesh.triangles));
        assert_eq!(g.mesh.tets, p.halo.tets);
    }
    let out = halo4d(&["check", "pair.glb"], dir.path());
    let table = String::from_utf8_lossy(&out.stdout);
    let header = table.lines().next().unwrap();
    assert!(
        header.contains("flat-halo") && header.contains("torus-halo"),
        "{table}"
    );
}

#[test]
fn check_passes_a_valid_halo_and_catches_faults_planted_in_its_files() {
    let dir = tempfile::tempdir().unwrap();
    let (glb, vtk, _) = patches(dir.path());
    for file in [&glb, &vtk] {
        let out = halo4d(&["check", file.to_str().unwrap()], dir.path());
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success(), "{}: {text}", file.display());
        assert!(text.contains("inverted") && text.contains("quad_mismatches"));
        assert!(
            text.contains("patches-halo") && text.contains("ok:"),
            "{text}"
        );
    }

    let halo = read_vtk(&std::fs::read(&vtk).unwrap()).unwrap();
    let planted = |name: &str, edit: &dyn Fn(&mut ImportedHalo), expect: &[&str]| {
        let mut h = halo.clone();
        edit(&mut h);
        let file = dir.path().join(name);
        std::fs::write(&file, ascii_vtk(&h, true)).unwrap();
        let out = halo4d(&["check", name], dir.path());
        let text = String::from_utf8_lossy(&out.stdout);
        assert_eq!(out.status.code(), Some(1), "{name}: {text}");
        let verdict = text.lines().last().unwrap();
        assert!(verdict.starts_with("FAILED patches-halo"), "{name}: {text}");
        for e in expect {
            assert!(verdict.contains(e), "{name}: `{e}` not in {verdict}");
        }
    };
    planted(
        "flipped.vtk",
        &|h| h.mesh.tets[7].swap(0, 1),
        &["1 inverted"],
    );
    // The same fault at scales where robust::orient3d would overflow (from about 1e103) or
    // underflow: still caught, the mesh scaled as a whole before deciding.
    for scale in [1e150, 1e-150, 1e300] {
        planted(
            &format!("flipped-{scale:e}.vtk"),
            &|h| {
                h.mesh.tets[7].swap(0, 1);
                for p in &mut h.mesh.positions {
                    *p = p.map(|x| x * scale);
                }
            },
            &["1 inverted"],
        );
    }
    // A coordinate 1e-100 of the largest: the tetrahedra at that vertex cannot be decided,
    // and are not passed.
    planted(
        "undecidable.vtk",
        &|h| {
            let t = h.mesh.tets[0];
            let p = &mut h.mesh.positions[t[0] as usize];
            p[0] = if p[0] == 0.0 {
                1e-100
            } else {
                p[0].signum() * 1e-100
            };
        },
        &["undecidable"],
    );
    // Every tetrahedron in halo4d's own orientation, which is VTK-negative: all inverted,
    // as ParaView's Mesh Quality would show them.
    let all = format!("{} inverted", halo.mesh.tets.len());
    planted(
        "vtk-negative.vtk",
        &|h| h.mesh.tets.iter_mut().for_each(|t| *t = file_order(*t)),
        &[&all],
    );
    planted(
        "duplicated.vtk",
        &|h| h.mesh.tets.push(h.mesh.tets[3]),
        &["1 duplicate_tets"],
    );
    planted(
        "missing.vtk",
        &|h| {
            h.mesh.tets.remove(10);
        },
        &["unexpected_boundary_faces"],
    );
    planted(
        "flat.vtk",
        &|h| {
            // d onto a: exactly flat, whatever the rounding.
            let [a, _, _, d] = h.mesh.tets[0];
            h.mesh.positions[d as usize] = h.mesh.positions[a as usize];
        },
        &["flat"],
    );

    // In the .glb: one tetrahedron's orientation flipped in the binary chunk.
    let mut bytes = std::fs::read(&glb).unwrap();
    let (tets, _) = halo_offsets(&bytes);
    let (first, second) = bytes.split_at_mut(tets + 4);
    first[tets..].swap_with_slice(&mut second[..4]);
    std::fs::write(dir.path().join("flipped.glb"), &bytes).unwrap();
    let out = halo4d(&["check", "flipped.glb"], dir.path());
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{text}");
    assert!(text.contains("FAILED patches-halo: 1 inverted"), "{text}");
}

#[test]
fn check_file_sees_every_prism_missing_from_a_halo() {
    // Tetrahedra cut away whole prisms at a time leave a valid shell of what is left: read
    // off the boundary, the surface shrinks with it and the halo passed. The file's own
    // surface triangles show what is missing.
    let dir = tempfile::tempdir().unwrap();
    let (glb, vtk, _) = patches(dir.path());
    let halo = read_vtk(&std::fs::read(&vtk).unwrap()).unwrap();
    let triangles = halo.mesh.surface_triangles.len();
    assert!(triangles > 0, "the .vtk lists its surface's triangles");
    let json = |bytes: &[u8]| -> Value {
        let len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        serde_json::from_slice(&bytes[20..20 + len]).unwrap()
    };
    let bytes = std::fs::read(&glb).unwrap();
    let tets_accessor = halo_mesh(&mut json(&bytes))["extras"]["halo"]["tetrahedra"]
        .as_u64()
        .unwrap() as usize;
    let total = halo.mesh.tets.len();
    // Each prism is six tetrahedra, in the surface's triangle order: the first half of the
    // tetrahedra is the first half of the prisms.
    for (name, kept) in [("none", 0), ("half", total / 2)] {
        let cut = with_json(&bytes, |j| {
            j["accessors"][tets_accessor]["count"] = (4 * kept).into();
        });
        std::fs::write(dir.path().join(format!("{name}.glb")), &cut).unwrap();
        let mut h = halo.clone();
        h.mesh.tets.truncate(kept);
        std::fs::write(dir.path().join(format!("{name}.vtk")), ascii_vtk(&h, true)).unwrap();
        for file in [format!("{name}.glb"), format!("{name}.vtk")] {
            let out = halo4d(&["check", &file], dir.path());
            let text = String::from_utf8_lossy(&out.stdout);
            let stderr = String::from_utf8_lossy(&out.stderr);
            if kept == 0 && out.status.code() == Some(2) {
                // No tetrahedron at all: refused as no halo, which is no pass either.
                assert!(stderr.contains(&file), "{file}: {stderr}");
                continue;
            }
            assert_eq!(out.status.code(), Some(1), "{file}: {text}{stderr}");
            let verdict = text.lines().last().unwrap();
            let missing = triangles - kept / 6;
            assert!(
                verdict.contains(&format!("{missing} missing_offset_faces"))
                    && verdict.contains("missing_surface_faces"),
                "{file}: {verdict}"
            );
        }
    }
    // The whole halo still passes, from either file.
    for file in [&glb, &vtk] {
        let out = halo4d(&["check", file.to_str().unwrap()], dir.path());
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stdout)
        );
    }
}

#[test]
fn a_halo_file_without_its_surface_triangles_never_claims_the_coverage() {
    // A halo .vtk of a halo4d that wrote no surface_triangles: read off the boundary alone,
    // half a halo is a valid shell of what is left, and no tetrahedron at all is vacuously
    // one. The check makes the checks that need no more, and says what it could not see.
    let dir = tempfile::tempdir().unwrap();
    let (_, vtk, _) = patches(dir.path());
    let halo = read_vtk(&std::fs::read(&vtk).unwrap()).unwrap();
    let total = halo.mesh.tets.len();
    let mut expected_exit = Vec::new();
    for (name, kept) in [("whole", total), ("half", total / 2), ("none", 0)] {
        let mut h = halo.clone();
        h.mesh.tets.truncate(kept);
        h.mesh.surface_triangles.clear();
        let file = format!("{name}.vtk");
        let text = ascii_vtk(&h, true).replace("surface_triangles 3 0 int\n", "");
        let text = text.replace("FIELD FieldData 4", "FIELD FieldData 3");
        std::fs::write(dir.path().join(&file), text).unwrap();
        let out = halo4d(&["check", &file], dir.path());
        let stdout = String::from_utf8_lossy(&out.stdout);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!stdout.contains("conform"), "{file}: {stdout}");
        if kept > 0 {
            assert!(
                stdout.contains("NOT checked: the coverage of the surface")
                    && stdout.contains("surface_triangles"),
                "{file}: {stdout}"
            );
        }
        let json = halo4d(&["check", &file, "--json"], dir.path());
        if json.status.code() != Some(2) {
            let v: Value = serde_json::from_slice(&json.stdout).unwrap();
            assert_eq!(v["unchecked"].as_array().unwrap().len(), 1, "{file}: {v}");
        }
        expected_exit.push((name, out.status.code(), stderr.into_owned()));
    }
    // The whole halo and its first half pass what can be checked (exit 0, saying what is
    // not); no tetrahedron at all is no pass.
    assert_eq!(expected_exit[0].1, Some(0), "{expected_exit:?}");
    assert_eq!(expected_exit[1].1, Some(0), "{expected_exit:?}");
    assert_ne!(expected_exit[2].1, Some(0), "{expected_exit:?}");
}

#[test]
fn unreadable_files_are_errors_of_the_cli_with_the_file_named() {
    let dir = tempfile::tempdir().unwrap();
    let (glb, _, _) = patches(dir.path());
    let bytes = std::fs::read(&glb).unwrap();
    std::fs::write(dir.path().join("cut.glb"), &bytes[..bytes.len() / 2]).unwrap();
    std::fs::write(dir.path().join("notes.txt"), "hello").unwrap();
    for (file, words) in [
        ("cut.glb", &["cut.glb", "truncated"][..]),
        (
            "notes.txt",
            &["notes.txt", "unknown file type", ".pvtu", ".msh"],
        ),
        ("absent.vtk", &["absent.vtk", "cannot read"]),
        // Not there, and no extension: not found, not "unknown file type".
        (
            "no-such-file",
            &["no-such-file", "cannot read", "No such file"],
        ),
    ] {
        let out = halo4d(&["check", file], dir.path());
        assert_unreadable(&out, file, words);
    }
}

#[test]
fn tetrahedra_without_the_halo_layout_are_certified_as_a_mesh() {
    // Another program's .vtk (no FIELD data) or an earlier halo4d's (no `layers`): certified
    // as a tetrahedral mesh, saying what cannot be checked; the exit status is that verdict.
    // The patches' halos cross where their sheets do (what a halo is for), so as one mesh
    // every copy fails on its boundary's self-intersections, and each planted fault adds
    // its own name.
    let dir = tempfile::tempdir().unwrap();
    let (_, vtk, _) = patches(dir.path());
    let mut halo = read_vtk(&std::fs::read(&vtk).unwrap()).unwrap();
    let bare = ascii_vtk(&halo, false);
    let earlier = ascii_vtk(&halo, true).replace("layers 1 1 int\n2\n", "nothing 1 1 int\n2\n");
    let tets = halo.mesh.tets.clone();
    // Half the tetrahedra: a mesh like the whole; only the layout could tell that a halo is
    // missing prisms.
    halo.mesh.tets.truncate(tets.len() / 2);
    let half = ascii_vtk(&halo, false);
    halo.mesh.tets = tets.clone();
    halo.mesh.tets[7].swap(0, 1);
    let inverted = ascii_vtk(&halo, false);
    halo.mesh.tets = tets.clone();
    halo.mesh.tets.push(tets[3]);
    let repeated = ascii_vtk(&halo, false);
    halo.mesh.tets = tets.clone();
    halo.mesh.tets.remove(11);
    let hole = ascii_vtk(&halo, false);
    for (file, text, names, words) in [
        (
            "bare.vtk",
            &bare,
            &[][..],
            &["another program wrote it"][..],
        ),
        (
            "earlier.vtk",
            &earlier,
            &[][..],
            &["an earlier halo4d wrote it"][..],
        ),
        ("half.vtk", &half, &[][..], &[][..]),
        (
            "inverted.vtk",
            &inverted,
            &["inverted"][..],
            &["FAILED 1 inverted"][..],
        ),
        (
            "repeated.vtk",
            &repeated,
            &["duplicate_tets", "overshared_faces", "volume_defect"][..],
            &["FAILED 1 duplicate_tets"][..],
        ),
        // A tetrahedron taken out leaves a notch whose faces are boundary faces.
        ("hole.vtk", &hole, &[][..], &[][..]),
    ] {
        std::fs::write(dir.path().join(file), text).unwrap();
        let out = halo4d(&["check", file], dir.path());
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert_eq!(out.status.code(), Some(1), "{file}: {stdout}");
        assert!(stdout.starts_with("not a halo: "), "{file}: {stdout}");
        assert!(
            stdout.contains("not checked: the halo's offset faces"),
            "{file}: {stdout}"
        );
        assert!(stdout.contains("\nmesh "), "{file}: {stdout}");
        assert!(!stdout.contains("quad_mismatches"), "{file}: {stdout}");
        for w in words {
            assert!(stdout.contains(w), "{file}: `{w}` not in {stdout}");
        }
        let checked = halo4d::check_file(&dir.path().join(file)).unwrap();
        let mut found = failure_names(&checked.failures());
        found.sort();
        let mut want: Vec<&str> = names.to_vec();
        want.push("self_intersections");
        want.sort();
        assert_eq!(found, want, "{file}");
    }
    // Two unit corner tetrahedra, one on each side of the z = 0 plane: 1/6 each.
    let two = halo4d::check_file(&fixture("meshes/two-tetrahedra.vtk")).unwrap();
    assert!(
        two.failures().is_empty() && two.plain.is_some(),
        "{}",
        two.text()
    );
    let s = two.halos[0].1;
    assert_eq!((s.tets, s.boundary_faces, s.interior_faces), (2, 6, 1));
    assert_eq!((s.volume, s.boundary_volume), (1.0 / 3.0, 1.0 / 3.0));
    assert_eq!((s.min_volume, s.max_volume), (1.0 / 6.0, 1.0 / 6.0));
    let checked = halo4d::check_file(&dir.path().join("half.vtk")).unwrap();
    let (_, stats) = &checked.halos[0];
    assert_eq!(stats.tets, tets.len() / 2);
    assert_eq!(stats.inverted + stats.flat + stats.overshared_faces, 0);
    assert!(stats.volume_defect < 1e-9, "{stats:?}");
}

/// `read_glb` fails with an error containing `words`.
fn glb_fails(bytes: &[u8], words: &[&str]) {
    let e = read_glb(bytes)
        .expect_err("accepted a broken .glb")
        .to_string();
    for w in words {
        assert!(e.contains(w), "`{w}` not in: {e}");
    }
}

/// `read_vtk` fails with an error containing `words`.
fn vtk_fails(bytes: &[u8], words: &[&str]) {
    let e = read_vtk(bytes)
        .expect_err("accepted a broken .vtk")
        .to_string();
    for w in words {
        assert!(e.contains(w), "`{w}` not in: {e}");
    }
}

#[test]
fn malformed_glb_files_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let (glb, _, products) = patches(dir.path());
    let good = std::fs::read(&glb).unwrap();
    let tets = products[0].halo.tets.len();
    assert_eq!(read_glb(&good).unwrap().len(), 1);

    glb_fails(b"", &["truncated", "header"]);
    glb_fails(&good[..11], &["truncated"]);
    glb_fails(&good[..100], &["truncated", "header says"]);
    glb_fails(&good[..good.len() - 4], &["truncated"]);
    let mut magic = good.clone();
    magic[..4].copy_from_slice(b"PLY\n");
    glb_fails(&magic, &["wrong magic"]);
    let mut version = good.clone();
    version[4] = 3;
    glb_fails(&version, &["version 3"]);
    let mut garbled = good.clone();
    garbled[20..30].copy_from_slice(b"{not json!");
    glb_fails(&garbled, &["not valid JSON"]);
    // What panics the gltf crate's own reading: a declared length under the header's 12
    // bytes, and a POSITION accessor out of range (its validation indexes it unchecked).
    let mut short = good.clone();
    short[8..12].copy_from_slice(&5u32.to_le_bytes());
    glb_fails(&short, &["the header says 5 bytes"]);
    glb_fails(
        &with_json(&good, |j| {
            halo_mesh(j)["primitives"][0]["attributes"]["POSITION"] = 999.into()
        }),
        &["accessors[999] does not exist"],
    );
    // A chunk that claims more than the file holds.
    let mut chunk = good.clone();
    chunk[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
    glb_fails(&chunk, &["truncated", "claims"]);

    let edited = |edit: &dyn Fn(&mut Value)| with_json(&good, |j| edit(j));
    glb_fails(
        &edited(&|j| halo_mesh(j)["extras"]["halo"]["tetrahedra"] = 999.into()),
        &[
            "no tetrahedra for patches-halo",
            "accessors[999], which does not exist",
        ],
    );
    // What another program leaves when it re-saves the file keeping the extras but not the
    // accessor: the number of a triangle index buffer (Blender 4.5), an accessor without our
    // name, or one of another type. Never read as tetrahedra.
    let no_tets = "this file has no tetrahedra for patches-halo (a program that re-saved it may have dropped them)";
    let triangles = edited(&|j| {
        let m = halo_mesh(j);
        m["extras"]["halo"]["tetrahedra"] = m["primitives"][0]["indices"].clone();
    });
    glb_fails(&triangles, &[no_tets, "accessors[", "which has no name"]);
    // Named as ours but read by a primitive: still not tetrahedra.
    glb_fails(
        &edited(&|j| {
            let m = halo_mesh(j);
            let a = m["primitives"][0]["indices"].clone();
            m["extras"]["halo"]["tetrahedra"] = a.clone();
            j["accessors"][a.as_u64().unwrap() as usize]["name"] = "patches-halo tetrahedra".into();
        }),
        &[no_tets, "a primitive reads as its indices"],
    );
    std::fs::write(dir.path().join("resaved.glb"), &triangles).unwrap();
    let out = halo4d(&["check", "resaved.glb"], dir.path());
    assert_unreadable(&out, "resaved.glb", &[no_tets]);
    let tets_accessor = |j: &Value| {
        halo_mesh(&mut j.clone())["extras"]["halo"]["tetrahedra"]
            .as_u64()
            .unwrap() as usize
    };
    glb_fails(
        &edited(&|j| {
            let a = tets_accessor(j);
            j["accessors"][a].as_object_mut().unwrap().remove("name");
        }),
        &[no_tets, "has no name", "`patches-halo tetrahedra`"],
    );
    glb_fails(
        &edited(&|j| {
            let a = tets_accessor(j);
            j["accessors"][a]["name"] = "other".into();
        }),
        &[no_tets, "is named `other`"],
    );
    glb_fails(
        &edited(&|j| {
            let a = tets_accessor(j);
            j["accessors"][a]["componentType"] = 5126.into();
        }),
        &[no_tets, "not SCALAR of UNSIGNED_INT"],
    );
    // The same accessors under JSON written anew (as pygltflib re-saves): still read.
    let rewritten = edited(&|j| {
        j["asset"]["generator"] = "another writer".into();
    });
    assert_eq!(read_glb(&rewritten).unwrap(), read_glb(&good).unwrap());
    glb_fails(
        &edited(&|j| halo_mesh(j)["extras"]["halo"]["tetrahedra"] = (-1).into()),
        &["tetrahedra", "not a non-negative integer"],
    );
    glb_fails(
        &edited(&|j| {
            halo_mesh(j)["extras"]["halo"]
                .as_object_mut()
                .unwrap()
                .remove("surface_vertices");
        }),
        &["no `surface_vertices`"],
    );
    // A halo without its layout's marker (as earlier versions wrote them), or another one.
    glb_fails(
        &edited(&|j| {
            halo_mesh(j)["extras"]["halo"]
                .as_object_mut()
                .unwrap()
                .remove("layers");
        }),
        &[
            "does not say its halo layout (`layers`)",
            "build the scene again",
        ],
    );
    glb_fails(
        &edited(&|j| halo_mesh(j)["extras"]["halo"]["layers"] = 1.into()),
        &["layers = 1", "2 layers of prisms"],
    );
    glb_fails(
        &edited(&|j| halo_mesh(j)["extras"]["halo"]["surface_vertices"] = 100_000.into()),
        &["surface_vertices = 100000", "offset and surface vertices"],
    );
    // Ten million tetrahedra claimed by a file of a hundred kilobytes.
    glb_fails(
        &edited(&|j| {
            let a = halo_mesh(j)["extras"]["halo"]["tetrahedra"]
                .as_u64()
                .unwrap() as usize;
            j["accessors"][a]["count"] = 40_000_000.into();
        }),
        &["claims 40000000 elements", "buffer view"],
    );
    glb_fails(
        &edited(&|j| {
            let a = halo_mesh(j)["extras"]["halo"]["tetrahedra"]
                .as_u64()
                .unwrap() as usize;
            j["accessors"][a]["count"] = (4 * tets - 2).into();
        }),
        &["not a multiple of 4"],
    );
    glb_fails(
        &edited(&|j| {
            let a = halo_mesh(j)["primitives"][0]["attributes"]["_T"]
                .as_u64()
                .unwrap() as usize;
            j["accessors"][a]["count"] = 3.into();
        }),
        &["_T has 3 values"],
    );
    glb_fails(
        &edited(&|j| {
            let a = halo_mesh(j)["primitives"][0]["attributes"]["POSITION"]
                .as_u64()
                .unwrap() as usize;
            let v = j["accessors"][a]["bufferView"].as_u64().unwrap() as usize;
            j["bufferViews"][v]["byteLength"] = u32::MAX.into();
        }),
        &["runs past"],
    );
    glb_fails(
        &edited(&|j| {
            for m in j["meshes"].as_array_mut().unwrap() {
                m.as_object_mut().unwrap().remove("extras");
            }
        }),
        &["no halo", "3 meshes"],
    );

    // Values in the binary chunk: an index out of range, a NaN coordinate.
    let (tets_at, positions_at) = halo_offsets(&good);
    let mut index = good.clone();
    index[tets_at + 8..tets_at + 12].copy_from_slice(&7_000_000u32.to_le_bytes());
    glb_fails(&index, &[no_tets, "names vertex 7000000 at index 2"]);
    let mut nan = good.clone();
    nan[positions_at + 16..positions_at + 20].copy_from_slice(&f32::NAN.to_le_bytes());
    glb_fails(
        &nan,
        &["patches-halo", "vertex 1 has a non-finite coordinate"],
    );
}

#[test]
fn malformed_vtk_files_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let (_, vtk, _) = patches(dir.path());
    let good = std::fs::read(&vtk).unwrap();
    let halo = read_vtk(&good).unwrap();
    let text = ascii_vtk(&halo, true);
    assert_eq!(read_vtk(text.as_bytes()).unwrap().mesh, halo.mesh);
    let (np, nt, n) = (
        halo.mesh.positions.len(),
        halo.mesh.tets.len(),
        halo.mesh.surface_vertices,
    );
    let cells = format!("CELLS {nt} {}", 5 * nt);
    let points = format!("POINTS {np} double\n");

    vtk_fails(b"", &["wrong magic"]);
    vtk_fails(b"ply\nformat ascii 1.0\n", &["wrong magic"]);
    vtk_fails(&good[..40], &["truncated"]);
    vtk_fails(&good[..good.len() / 2], &["claimed", "left"]);
    vtk_fails(&good[..good.len() - 9], &["SCALARS d_orig", "claimed"]);
    let replace = |from: &str, to: &str| {
        assert!(text.contains(from), "{from}");
        text.replacen(from, to, 1)
    };
    vtk_fails(replace("ASCII", "TEXT").as_bytes(), &["ASCII or BINARY"]);
    // A huge line is quoted in part, not whole.
    for long in [
        format!("DATASET {}", "X".repeat(70_000)),
        "Y".repeat(70_000),
    ] {
        let e = read_vtk(replace("DATASET UNSTRUCTURED_GRID", &long).as_bytes())
            .unwrap_err()
            .to_string();
        assert!(
            e.len() < 300 && e.contains("..."),
            "{} bytes: {e:.200}",
            e.len()
        );
    }
    let rho = format!("rho 1 1 double\n{}\n", halo.params.rho.unwrap());
    for bad in ["nan", "inf", "-inf"] {
        vtk_fails(
            replace(&rho, &format!("rho 1 1 double\n{bad}\n")).as_bytes(),
            &["FIELD value rho", "not a finite number"],
        );
    }
    vtk_fails(
        replace("UNSTRUCTURED_GRID", "POLYDATA").as_bytes(),
        &["POLYDATA", "UNSTRUCTURED_GRID"],
    );
    vtk_fails(
        replace(
            &format!("CELL_TYPES {nt}\n10\n"),
            &format!("CELL_TYPES {nt}\n12\n"),
        )
        .as_bytes(),
        &["cell 0 has 4 points", "a cell of type 12 has 8"],
    );
    vtk_fails(
        replace(
            &format!("CELL_TYPES {nt}\n10\n"),
            &format!("CELL_TYPES {}\n", nt - 1),
        )
        .as_bytes(),
        &[&format!("CELL_TYPES lists {} cells, CELLS {nt}", nt - 1)],
    );
    vtk_fails(
        replace(&format!("{cells}\n4 "), &format!("{cells}\n3 ")).as_bytes(),
        &["cell 0 has 3 points"],
    );
    vtk_fails(
        replace(
            &format!("POINT_DATA {np}"),
            &format!("POINT_DATA {}", np - 1),
        )
        .as_bytes(),
        &[&format!(
            "POINT_DATA is for {} points, POINTS lists {np}",
            np - 1
        )],
    );
    // Ten million tetrahedra, or a billion points, claimed in a small file.
    vtk_fails(
        replace(&cells, "CELLS 10000000 50000000").as_bytes(),
        &["CELLS", "50000000 values claimed"],
    );
    vtk_fails(
        replace(&points, "POINTS 1000000000 double\n").as_bytes(),
        &["POINTS", "3000000000 values claimed"],
    );
    // An extra first cell that names a point beyond the last.
    let index = replace(
        &format!("{cells}\n"),
        &format!("CELLS {} {}\n4 0 1 2 {}\n", nt + 1, 5 * nt + 5, 5 * np),
    );
    vtk_fails(
        index
            .replacen(
                &format!("CELL_TYPES {nt}\n"),
                &format!("CELL_TYPES {}\n10\n", nt + 1),
                1,
            )
            .as_bytes(),
        &[&format!(
            "cell 0 names point {}, but there are {np} points",
            5 * np
        )],
    );
    let points_at = text.find(&points).unwrap() + points.len();
    let mut nan = text.clone();
    let line_end = points_at + text[points_at..].find('\n').unwrap();
    nan.replace_range(points_at..line_end, "0 NaN 0");
    vtk_fails(nan.as_bytes(), &["vertex 0 has a non-finite coordinate"]);
    let layout = format!("surface_vertices 1 1 int\n{n}\n");
    vtk_fails(
        replace(&layout, &format!("surface_vertices 1 1 int\n{np}\n")).as_bytes(),
        &[
            &format!("surface_vertices = {np}"),
            &format!("{np} vertices"),
        ],
    );
    vtk_fails(
        replace(&layout, "surface_vertices 1 1 double\n4.5\n").as_bytes(),
        &["surface_vertices must be a non-negative integer"],
    );
    vtk_fails(
        replace("layers 1 1 int\n2\n", "layers 1 1 int\n1\n").as_bytes(),
        &["layers = 1", "2 layers of prisms"],
    );
    vtk_fails(
        replace("layers 1 1 int\n2\n", "nothing 1 1 int\n2\n").as_bytes(),
        &["does not say its halo layout (`layers`)"],
    );
    vtk_fails(
        ascii_vtk(&halo, false).as_bytes(),
        &["lacks the halo layout", "surface_vertices"],
    );
    vtk_fails(
        replace("SCALARS t double", "SPLINES t double").as_bytes(),
        &["SPLINES"],
    );
    assert!(matches!(
        read_vtk(ascii_vtk(&halo, false).as_bytes()),
        Err(ImportError::NoHalo(_))
    ));
}

#[test]
fn no_cut_or_corrupted_file_panics_the_readers() {
    let dir = tempfile::tempdir().unwrap();
    let (glb, vtk, _) = patches(dir.path());
    let halo = read_vtk(&std::fs::read(&vtk).unwrap()).unwrap();
    let files = [
        std::fs::read(&glb).unwrap(),
        std::fs::read(&vtk).unwrap(),
        ascii_vtk(&halo, true).into_bytes(),
    ];
    let mut rng = Rng(0x4a10);
    for (k, good) in files.iter().enumerate() {
        let parse = |bytes: &[u8]| {
            if k == 0 {
                read_glb(bytes).map(|_| ())
            } else {
                read_vtk(bytes).map(|_| ())
            }
        };
        for cut in (0..good.len()).step_by(good.len() / 200) {
            let result = parse(&good[..cut]);
            // An ASCII file cut inside its last number can still be a valid file.
            assert!(k == 2 || result.is_err(), "file {k} cut at {cut}");
        }
        for _ in 0..300 {
            let mut bytes = good.clone();
            for _ in 0..1 + rng.below(4) {
                let at = rng.below(bytes.len());
                bytes[at] = rng.bits() as u8;
            }
            let _ = parse(&bytes);
        }
    }
}
