//! The command line, run as a user runs it.

use crate::common::{fixture, halo4d, halo4d_with};

#[test]
fn build_without_a_scene_writes_the_default_into_exports() {
    let dir = tempfile::tempdir().unwrap();
    let out = halo4d(&["build", "--quiet"], dir.path());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for f in [
        "spun-trefoil.glb",
        "spun-trefoil.ply",
        "spun-trefoil-halo.vtk",
        "report.json",
    ] {
        assert!(
            dir.path().join("exports/spun-trefoil").join(f).is_file(),
            "{f} missing"
        );
    }
}

#[test]
fn a_broken_scene_fails_with_the_file_and_field_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let scene = fixture("broken/fermat-n-out-of-range.json");
    let out = halo4d(
        &["build", scene.to_str().unwrap(), "--out", "o"],
        dir.path(),
    );
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("fermat-n-out-of-range.json") && err.contains("surfaces[0].surface.n"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    assert!(!dir.path().join("o").exists());
}

#[test]
fn list_shows_every_surface_with_defaults_and_help_works_everywhere() {
    let dir = tempfile::tempdir().unwrap();
    let out = halo4d(&["list"], dir.path());
    let text = String::from_utf8_lossy(&out.stdout);
    for s in halo4d::surfaces::Surface::catalogue() {
        assert!(text.contains(s.type_name()), "{text}");
    }
    assert!(
        text.contains("\"twists\":2") && text.contains("\"n\":4"),
        "{text}"
    );
    // The formula's and the mesh's examples are whole scenes (which load: `scene.rs`).
    let example = |ty: &str| {
        let line = text
            .lines()
            .skip_while(|l| !l.starts_with(ty))
            .find_map(|l| l.trim().strip_prefix("a scene: "))
            .unwrap_or_else(|| panic!("no example for {ty}: {text}"));
        serde_json::from_str::<serde_json::Value>(line).unwrap()
    };
    let formula = example("formula");
    halo4d::Scene::parse(&formula.to_string(), "e.json").unwrap();
    assert_eq!(example("mesh")["surfaces"][0]["surface"]["type"], "mesh");
    for args in [&["--help"][..], &["build", "--help"], &["list", "--help"]] {
        let out = halo4d(args, dir.path());
        assert!(out.status.success() && !out.stdout.is_empty(), "{args:?}");
    }
    let out = halo4d(&["build", "--bogus"], dir.path());
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn a_budget_too_small_for_the_tolerance_warns_and_reports_incomplete() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("tight.json");
    std::fs::write(
        &scene,
        r#"{ "name": "tight", "surfaces": [ { "surface": { "type": "spun_trefoil" } } ],
             "sampling": { "method": "adaptive", "tolerance": 1e-7, "max_triangles": 2000 },
             "outputs": { "glb": false, "ply": false } }"#,
    )
    .unwrap();
    // So coarse a knot gets curve samples wrong: the build is not verified, which is not
    // what this test is about.
    let out = halo4d(
        &[
            "build",
            "tight.json",
            "--out",
            "o",
            "-q",
            "--allow-unverified",
        ],
        dir.path(),
    );
    assert!(out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("warning") && err.contains("max_triangles = 2000"),
        "{err}"
    );
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("o/report.json")).unwrap()).unwrap();
    let sampling = &report["surfaces"][0]["sampling"];
    assert_eq!(sampling["complete"], false, "{sampling}");
    assert!(sampling["triangles"].as_u64().unwrap() <= 2000);
    assert!(sampling["max_error"].as_f64().unwrap() > sampling["tolerance"].as_f64().unwrap());
    assert_eq!(report["warnings"].as_array().unwrap().len(), 1);
}

#[test]
fn sweep_rows_say_whether_their_curves_are_the_certified_ones() {
    // A paraboloid z = u² + v² over a square has no double curve, and the certificate
    // proves it: every row's mesh agrees (`=`), and the table says what the certificate
    // cost.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("square.json"),
        r#"{ "name": "square", "surfaces": [ { "name": "square", "surface": { "type": "formula",
             "x": "u", "y": "v", "z": "u*u + v*v", "w": "0", "u": [-1, 1], "v": [-1, 1] } } ] }"#,
    )
    .unwrap();
    let out = halo4d(
        &["sweep", "square.json", "--tolerances", "1e-2,1e-3", "-q"],
        dir.path(),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(
        table.contains("certified: 0 closed and 0 open curves, in"),
        "{table}"
    );
    let rows: Vec<&str> = table.lines().filter(|l| l.starts_with("square ")).collect();
    assert_eq!(rows.len(), 3, "{table}");
    assert!(rows[..2].iter().all(|l| l.ends_with(" =")), "{table}");
    let csv =
        std::fs::read_to_string(dir.path().join("exports/reports/speed_vs_error.csv")).unwrap();
    for line in csv.lines().skip(1) {
        let r: Vec<&str> = line.split(',').collect();
        assert_eq!(&r[15..19], ["0", "0", "0", "0"], "{csv}");
    }
}

#[test]
fn sweep_writes_csv_and_plot_for_a_scene() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("two.json");
    std::fs::write(
        &scene,
        r#"{ "name": "two", "surfaces": [
             { "name": "torus", "surface": { "type": "flat_torus" } },
             { "name": "knot", "surface": { "type": "spun_trefoil" } } ] }"#,
    )
    .unwrap();
    let out = halo4d(
        &["sweep", "two.json", "--tolerances", "1e-2,3e-3", "-q"],
        dir.path(),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv =
        std::fs::read_to_string(dir.path().join("exports/reports/speed_vs_error.csv")).unwrap();
    let mut lines = csv.lines();
    // The curve columns come after the sampling's.
    assert_eq!(
        lines.next().unwrap(),
        "surface,method,tolerance,triangles,ms,max_error,rms_error,met,grid,\
         curve_ms,refine_ms,curve_error,refined_residual,curve_points,not_converged,closed,open,\
         certified_closed,certified_open,certify_ms"
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 2 * 2 * 2, "{csv}");
    for r in &rows {
        assert_eq!(r.len(), 20, "{csv}");
        let (tol, max): (f64, f64) = (r[2].parse().unwrap(), r[5].parse().unwrap());
        assert_eq!(r[7], "true", "{csv}");
        assert!(max <= tol && max > 0.0, "{csv}");
        let (points, not_converged): (usize, usize) =
            (r[13].parse().unwrap(), r[14].parse().unwrap());
        assert!(not_converged <= points, "{csv}");
        for cell in &r[9..13] {
            let x: f64 = cell.parse().unwrap();
            assert!(x.is_finite() && x >= 0.0, "{csv}");
        }
    }
    for png in ["speed_vs_error.png", "curves_vs_error.png"] {
        let png = image::open(dir.path().join("exports/reports").join(png)).unwrap();
        assert_eq!((png.width(), png.height()), (1200, 800));
    }
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(table.contains("ratio") && table.contains("knot"), "{table}");
    // A bad flag value names the flag.
    let out = halo4d(&["sweep", "--tolerances", "2"], dir.path());
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--tolerances"));

    // The smallest budget: every grid within it, and one that meets 0.5 marked so.
    let args = ["--tolerances", "0.5", "--max-triangles", "64", "--quiet"];
    let out = halo4d(
        &[&["sweep", "two.json", "--out", "tiny"][..], &args].concat(),
        dir.path(),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = std::fs::read_to_string(dir.path().join("tiny/speed_vs_error.csv")).unwrap();
    for r in csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect::<Vec<_>>())
    {
        let (triangles, max): (usize, f64) = (r[3].parse().unwrap(), r[5].parse().unwrap());
        assert!(triangles <= 64, "{csv}");
        assert_eq!(r[7] == "true", max <= 0.5, "{csv}");
    }
    // A budget below a surface's coarsest grid is refused, naming it.
    std::fs::write(
        dir.path().join("quartic.json"),
        r#"{ "name": "q", "surfaces": [ { "surface": { "type": "fermat" } } ] }"#,
    )
    .unwrap();
    let out = halo4d(
        &[&["sweep", "quartic.json", "--out", "q"][..], &args].concat(),
        dir.path(),
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("--max-triangles: must be 512 to 20000000 triangles, got 64")
            && err.contains("the coarsest grid of `fermat`"),
        "{err}"
    );
}

#[test]
fn sweep_measures_the_curves_of_every_mesh_of_the_flat_torus() {
    let dir = tempfile::tempdir().unwrap();
    let scene = fixture("scenes/flat-torus.json");
    let out = halo4d(
        &[
            "sweep",
            scene.to_str().unwrap(),
            "--tolerances",
            "1e-2,1e-3,1e-4",
            "--out",
            "o",
            "-q",
        ],
        dir.path(),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = std::fs::read_to_string(dir.path().join("o/speed_vs_error.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let column = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 2 * 3, "{csv}");
    let number = |r: &[&str], name: &str| -> f64 { r[column(name)].parse().unwrap() };
    // The certificate is the true surface's, whatever the mesh: the same on every row, and
    // its time too.
    let certified: Vec<[&str; 3]> = rows
        .iter()
        .map(|r| ["certified_closed", "certified_open", "certify_ms"].map(|c| r[column(c)]))
        .collect();
    assert!(certified.windows(2).all(|w| w[0] == w[1]), "{csv}");
    assert!(number(&rows[0], "certify_ms") > 0.0, "{csv}");
    for method in ["adaptive", "uniform"] {
        let mine: Vec<&Vec<&str>> = rows.iter().filter(|r| r[1] == method).collect();
        let errors: Vec<f64> = mine.iter().map(|r| number(r, "curve_error")).collect();
        for r in &mine {
            // Two arcs ending at four cross-caps, refined to rounding.
            assert!(number(r, "curve_points") > 0.0, "{csv}");
            assert!(
                number(r, "curve_error") > number(r, "refined_residual"),
                "{csv}"
            );
            assert!(number(r, "refined_residual") < 1e-12, "{csv}");
            assert!(number(r, "curve_error") < 2e-2, "{csv}");
        }
        // Finer meshes, finer curves. The adaptive meshes' curve error need not fall at
        // every step: it is largest next to the cross-caps, where the two sheets meet at a
        // small angle and a small error of the surface moves the curve far, and a finer
        // mesh puts curve points nearer to them (at 1e-3 and 1e-4 it rises, 7.5e-4 to
        // 1.7e-3). The uniform grids' falls at every step.
        assert!(errors[2] < errors[0], "{method}: {errors:?}\n{csv}");
        if method == "uniform" {
            assert!(
                errors.windows(2).all(|e| e[1] < e[0]),
                "{method}: {errors:?}\n{csv}"
            );
        }
    }
    let png = image::open(dir.path().join("o/curves_vs_error.png")).unwrap();
    assert_eq!((png.width(), png.height()), (1200, 800));
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(
        table.contains("crv err") && table.contains("refined"),
        "{table}"
    );
}

/// Every file of a folder (hidden ones too) with its bytes.
fn folder(dir: &std::path::Path) -> Vec<(String, Vec<u8>)> {
    let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .map(|p| {
            let bytes = std::fs::read(&p).unwrap();
            (p.file_name().unwrap().to_string_lossy().into_owned(), bytes)
        })
        .collect();
    files.sort();
    files
}

/// The patches fixture with `edit` applied to its JSON, written to `dir/<name>.json`.
fn patches_scene(dir: &std::path::Path, name: &str, edit: &str) -> String {
    let mut scene: serde_json::Value =
        serde_json::from_slice(&std::fs::read(fixture("scenes/patches.json")).unwrap()).unwrap();
    let edit: serde_json::Value = serde_json::from_str(edit).unwrap();
    for (k, v) in edit.as_object().unwrap() {
        scene[k] = v.clone();
    }
    let file = format!("{name}.json");
    std::fs::write(dir.join(&file), serde_json::to_vec(&scene).unwrap()).unwrap();
    file
}

#[test]
fn a_build_that_fails_at_its_last_stage_leaves_the_previous_build_unchanged() {
    let dir = tempfile::tempdir().unwrap();
    let good = patches_scene(dir.path(), "good", "{}");
    let out = halo4d(&["build", "-q", &good, "--out", "o"], dir.path());
    assert!(out.status.success());
    let before = folder(&dir.path().join("o"));
    assert!(before.iter().any(|(f, _)| f == "patches.png"));
    // Valid as a scene, but the picture fails: an orthographic eye inside the scene, after
    // every other file was made.
    let bad = patches_scene(
        dir.path(),
        "bad",
        r#"{"camera": {"projection": "orthographic", "distance": 0.5},
            "halo": {"rho": 0.02}}"#,
    );
    let out = halo4d(&["build", "-q", &bad, "--out", "o"], dir.path());
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("camera") || err.contains("distance"), "{err}");
    assert_eq!(folder(&dir.path().join("o")), before, "the folder changed");
}

#[test]
fn a_killed_build_leaves_the_previous_build_and_its_lock_is_taken_over() {
    let dir = tempfile::tempdir().unwrap();
    let out = halo4d(&["build", "-q", "--out", "o"], dir.path());
    assert!(out.status.success());
    let o = dir.path().join("o");
    let before = folder(&o);
    // The same scene with another halo width: every file would differ. Killed as soon as it takes
    // the folder's lock, i.e. while it writes its files (the picture alone takes a second).
    let mut other: serde_json::Value =
        serde_json::from_slice(&std::fs::read(fixture("scenes/default.json")).unwrap()).unwrap();
    other["halo"]["gap_px"] = 10.into();
    std::fs::write(
        dir.path().join("other.json"),
        serde_json::to_vec(&other).unwrap(),
    )
    .unwrap();
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_halo4d"))
        .args(["build", "-q", "other.json", "--out", "o"])
        .current_dir(dir.path())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let lock = o.join(halo4d::export::LOCK);
    while !lock.exists() {
        assert!(child.try_wait().unwrap().is_none(), "it finished unkilled");
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    // The previous files, unchanged; what the killed build left is hidden and temporary.
    let after = folder(&o);
    let visible = |files: &[(String, Vec<u8>)]| -> Vec<(String, Vec<u8>)> {
        files
            .iter()
            .filter(|(f, _)| !f.starts_with('.'))
            .cloned()
            .collect()
    };
    assert_eq!(visible(&after), visible(&before), "the folder changed");
    assert!(after.iter().all(|(f, _)| !f.starts_with('.')
        || f.ends_with(".partial")
        || f.starts_with(halo4d::export::LOCK)));
    // Its lock names a process that is gone: the next build takes it over.
    let out = halo4d(&["build", "-q", "other.json", "--out", "o"], dir.path());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        folder(&o).iter().all(|(f, _)| !f.starts_with('.')),
        "leftovers"
    );
}

#[test]
fn a_second_build_into_a_folder_in_use_fails_at_once_naming_the_other() {
    let dir = tempfile::tempdir().unwrap();
    let o = dir.path().join("o");
    std::fs::create_dir(&o).unwrap();
    // This test's own process holds the lock, as a running build would.
    let me = std::process::id().to_string();
    std::fs::write(o.join(halo4d::export::LOCK), &me).unwrap();
    let scene = patches_scene(dir.path(), "p", "{}");
    let out = halo4d(&["build", "-q", &scene, "--out", "o"], dir.path());
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains(&format!("another halo4d build (process {me})"))
            && err.contains(".halo4d-build.lock"),
        "{err}"
    );
    assert_eq!(folder(&o).len(), 1, "it wrote something");
}

#[test]
fn an_unverified_build_writes_its_files_marked_and_exits_3_unless_allowed() {
    let dir = tempfile::tempdir().unwrap();
    // rho far beyond what the torus allows, with folds reported rather than shrunk: inverted
    // tetrahedra, and curve samples the folded halos get wrong.
    let scene = r#"{ "name": "unv", "surfaces": [ { "surface": { "type": "flat_torus" } } ],
        "sampling": { "method": "uniform", "u": 16, "v": 16 },
        "view": { "rotation": { "yw": 30 } },
        "halo": { "rho": 0.3, "fold": "report" }, "outputs": { "png": false } }"#;
    std::fs::write(dir.path().join("unv.json"), scene).unwrap();
    let out = halo4d(&["build", "-q", "unv.json", "--out", "o"], dir.path());
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{err}");
    assert!(
        err.contains("UNVERIFIED flat_torus-halo: ") && err.contains(" inverted"),
        "{err}"
    );
    assert!(err.contains("--allow-unverified"), "{err}");
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("o/report.json")).unwrap()).unwrap();
    assert_eq!(report["verified"], false);
    let failures = report["failures"].as_array().unwrap();
    assert!(
        failures
            .iter()
            .any(|f| f.as_str().unwrap().contains("inverted"))
    );
    // The .glb says so too, in its asset extras.
    let glb =
        gltf::Gltf::from_slice(&std::fs::read(dir.path().join("o/unv.glb")).unwrap()).unwrap();
    let extras: serde_json::Value =
        serde_json::from_str(glb.as_json().asset.extras.as_ref().unwrap().get()).unwrap();
    assert_eq!(extras["halo4d"]["verified"], false);
    assert_eq!(&extras["halo4d"]["failures"], &report["failures"]);
    // `halo4d check` agrees that the halo fails.
    let out = halo4d(&["check", "o/unv.glb"], dir.path());
    assert_eq!(out.status.code(), Some(1));
    let out = halo4d(
        &[
            "build",
            "-q",
            "unv.json",
            "--out",
            "o",
            "--allow-unverified",
        ],
        dir.path(),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("UNVERIFIED"));
    // With no file that records the verdict, the message names none.
    let quiet = scene.replace(
        r#""outputs": { "png": false }"#,
        r#""outputs": { "png": false, "glb": false, "vtk": false, "ply": false, "report": false, "verify": true }"#,
    );
    std::fs::write(dir.path().join("none.json"), quiet).unwrap();
    let out = halo4d(&["build", "-q", "none.json", "--out", "n"], dir.path());
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{err}");
    assert!(
        err.contains("none records the verdict (outputs.report and outputs.glb are off)")
            && !err.contains("report.json,"),
        "{err}"
    );

    // A verified build says so.
    let out = halo4d(&["build", "-q", "--out", "d"], dir.path());
    assert!(out.status.success());
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("d/report.json")).unwrap()).unwrap();
    assert_eq!(
        (&report["verified"], &report["failures"]),
        (&true.into(), &serde_json::json!([]))
    );
}

#[test]
fn scenes_beyond_what_f32_and_the_predicates_hold_are_refused_and_the_rest_write_only_finite_numbers()
 {
    let dir = tempfile::tempdir().unwrap();
    let scene = |scale: f64| {
        format!(
            r#"{{"name": "s", "surfaces": [{{"surface": {{"type": "spun_trefoil", "scale": {scale:e}}}}}],
                "sampling": {{"method": "uniform", "u": 8, "v": 8}}, "outputs": {{"png": false}}}}"#
        )
    };
    for (scale, words) in [
        (
            1e39,
            &["reaches a coordinate of", "beyond 1e30", "make it smaller"][..],
        ),
        (1e-300, &["across, less than 1e-30", "make them larger"]),
    ] {
        std::fs::write(dir.path().join("s.json"), scene(scale)).unwrap();
        let out = halo4d(&["build", "-q", "s.json", "--out", "refused"], dir.path());
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{scale:e}: {err}");
        for w in words {
            assert!(err.contains(w), "{scale:e}: `{w}` not in {err}");
        }
        assert!(
            !dir.path().join("refused").exists(),
            "{scale:e}: wrote files"
        );
    }
    // Large and small but within range: every float of the .glb is finite, and report.json
    // has no null (serde_json writes a non-finite number as null).
    for scale in [1e25, 1e-25] {
        std::fs::write(dir.path().join("s.json"), scene(scale)).unwrap();
        let o = format!("o{scale:e}");
        let out = halo4d(
            &["build", "-q", "s.json", "--out", &o, "--allow-unverified"],
            dir.path(),
        );
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let bytes = std::fs::read(dir.path().join(&o).join("s.glb")).unwrap();
        let gltf = gltf::Gltf::from_slice(&bytes).unwrap();
        let blob = gltf.blob.as_deref().unwrap();
        for a in gltf.accessors() {
            if a.data_type() != gltf::accessor::DataType::F32 {
                continue;
            }
            let view = a.view().unwrap();
            let n = a.count() * a.dimensions().multiplicity();
            let floats = blob[view.offset() + a.offset()..][..4 * n]
                .chunks_exact(4)
                .map(|c| f32::from_le_bytes(c.try_into().unwrap()));
            assert!(
                floats.clone().all(f32::is_finite),
                "{scale:e}: accessor {}",
                a.index()
            );
        }
        let report = std::fs::read_to_string(dir.path().join(&o).join("report.json")).unwrap();
        assert!(!report.contains("null"), "{scale:e}: a null in report.json");
    }
}

#[test]
fn a_build_beyond_the_memory_limit_is_refused_before_the_halos_and_writes_nothing() {
    // A build of the default scene's 13,000 triangles needs more than 10 MB: refused
    // under a limit of 10 MB with the estimate and what to change, built under 1 GB.
    let dir = tempfile::tempdir().unwrap();
    let out = halo4d_with(
        &["build", "--out", "out"],
        dir.path(),
        &[("HALO4D_MAX_MEMORY", "0.01")],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    for words in [
        "triangles would need about 0.0",
        "more than the limit of 0.01 GB (HALO4D_MAX_MEMORY)",
        "sampling.tolerance",
    ] {
        assert!(err.contains(words), "{words}: {err}");
    }
    assert!(!dir.path().join("out").exists());
    let out = halo4d_with(
        &["build", "--quiet", "--out", "out"],
        dir.path(),
        &[("HALO4D_MAX_MEMORY", "1")],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(dir.path().join("out").join("report.json").exists());
}

#[test]
fn the_report_s_timings_and_memory_agree_with_the_process_s() {
    // The default scene with its picture, timed from outside: the report's total is the
    // process's wall time but for its start and exit, its stages add up to the total, and
    // the estimated memory is a guard that does not fall short of the peak the system
    // measured (VmHWM, what `/usr/bin/time` reports) and is not far above it: at this size
    // the peak moves by 5% between runs and the estimate is high by 15 to 25%
    // (docs/PERFORMANCE.md). `cargo bench --bench scale` compares them at 100k to 10M
    // triangles.
    let dir = tempfile::tempdir().unwrap();
    let start = std::time::Instant::now();
    let out = halo4d(&["build", "--quiet", "--out", "out"], dir.path());
    let wall = start.elapsed().as_secs_f64() * 1e3;
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("out/report.json")).unwrap())
            .unwrap();
    let t = report["timings_ms"].as_object().unwrap();
    let total = t["total"].as_f64().unwrap();
    let stages: f64 = t
        .iter()
        .filter(|(k, _)| *k != "total")
        .map(|(_, v)| v.as_f64().unwrap())
        .sum();
    for stage in ["setup", "guards", "free", "export", "render", "halo"] {
        assert!(t.contains_key(stage), "no `{stage}` in {t:?}");
    }
    assert!(
        stages <= total && stages >= 0.99 * total - 2.0,
        "{stages} of {total} ms: {t:?}"
    );
    // Starting and ending a process takes milliseconds; other tests share the cores.
    assert!(total < wall, "{total} ms reported, {wall} ms measured");
    assert!(
        wall - total < 0.02 * wall + 100.0,
        "{total} ms reported, {wall} ms measured"
    );
    let memory = &report["memory"];
    let (estimate, peak) = (
        memory["estimate_gb"].as_f64().unwrap(),
        memory["peak_gb"].as_f64().unwrap(),
    );
    assert!(
        peak <= 1.05 * estimate && estimate <= 1.35 * peak,
        "estimate {estimate} GB, peak {peak} GB"
    );
}

#[test]
fn a_build_runs_only_the_stages_its_outputs_need() {
    let dir = tempfile::tempdir().unwrap();
    let build = |name: &str, outputs: &str| {
        let file = patches_scene(dir.path(), name, &format!(r#"{{"outputs": {outputs}}}"#));
        let out = halo4d(&["build", "--quiet", &file, "--out", name], dir.path());
        (out, dir.path().join(name))
    };
    let report = |folder: &std::path::Path| -> serde_json::Value {
        serde_json::from_slice(&std::fs::read(folder.join("report.json")).unwrap()).unwrap()
    };
    let stages = |r: &serde_json::Value| {
        let s = &r["stages"];
        [&s["halos"], &s["curves"], &s["verify"]].map(|b| b.as_bool().unwrap())
    };
    let none = r#"{"glb": false, "ply": false, "vtk": false, "png": false, "report": true"#;

    // Surfaces for MeshLab: the curves for `-curves.ply`, no halo, no verification.
    let (out, folder) = build("ply", &format!(r#"{none}, "ply": true}}"#));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r = report(&folder);
    assert_eq!(stages(&r), [false, true, false], "{r}");
    assert!(r["halo_verification"].is_null() && r["surfaces"][0]["halo"].is_null());
    assert!(r["curves"]["count"].as_u64().unwrap() > 0);
    assert_eq!(
        (
            r["timings_ms"]["halo"].as_f64(),
            r["timings_ms"]["verify"].as_f64()
        ),
        (Some(0.0), Some(0.0))
    );
    let names: Vec<String> = folder_names(&folder);
    assert_eq!(names, ["patches-curves.ply", "patches.ply", "report.json"]);

    // Only the report: nothing after the projection.
    let (out, folder) = build("bare", &format!("{none}}}"));
    assert!(out.status.success());
    let r = report(&folder);
    assert_eq!(stages(&r), [false, false, false], "{r}");
    assert!(r["curves"].is_null());

    // The verification asked for without a halo file: its verdict in the report.
    let (out, folder) = build("verify", &format!(r#"{none}, "verify": true}}"#));
    assert!(out.status.success());
    let r = report(&folder);
    assert_eq!(stages(&r), [true, true, true], "{r}");
    assert!(
        r["halo_verification"]["correct"].as_u64().unwrap() > 0,
        "{r}"
    );
    assert_eq!(r["halo_verification"]["wrong"], 0);
    assert_eq!(folder_names(&folder), ["report.json"]);

    // Halo files are never written unverified.
    let (out, folder) = build("no", r#"{"glb": true, "verify": false}"#);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("outputs.verify") && err.contains("always verified"),
        "{err}"
    );
    assert!(!folder.exists());
}

#[test]
fn a_picture_gets_its_halos_whatever_files_the_scene_writes() {
    // `halo4d render` makes a picture, so it runs the stages a picture needs even for a
    // scene that writes only its report: the same PNG as with every output.
    let dir = tempfile::tempdir().unwrap();
    let small = r#""render": {"width": 96, "height": 96, "samples": 1}"#;
    let mut pictures = Vec::new();
    for (name, outputs) in [
        ("all", "{}"),
        (
            "report",
            r#"{"glb": false, "ply": false, "vtk": false, "png": false}"#,
        ),
    ] {
        let file = patches_scene(
            dir.path(),
            name,
            &format!(r#"{{"outputs": {outputs}, {small}}}"#),
        );
        let png = format!("{name}.png");
        let out = halo4d(&["render", &file, "--out", &png, "--quiet"], dir.path());
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        pictures.push(std::fs::read(dir.path().join(png)).unwrap());
    }
    assert_eq!(pictures[0], pictures[1]);
}

fn folder_names(dir: &std::path::Path) -> Vec<String> {
    folder(dir).into_iter().map(|(name, _)| name).collect()
}

#[test]
fn render_writes_beside_the_build_s_picture_and_refuses_an_out_that_is_not_a_png_file() {
    let dir = tempfile::tempdir().unwrap();
    let small = r#"{"render": {"width": 64, "height": 64, "samples": 1, "style": "stipple"}}"#;
    let file = patches_scene(dir.path(), "small", small);
    // The build's picture stays; the render goes beside it, and says what it drew.
    let build = halo4d(&["build", "-q", &file], dir.path());
    assert!(build.status.success());
    let built = dir.path().join("exports/patches/patches.png");
    let before = std::fs::read(&built).unwrap();
    let out = halo4d(
        &["render", &file, "--quiet", "--style", "shaded"],
        dir.path(),
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("64 x 64 shaded picture, exact halos"), "{err}");
    assert!(
        dir.path()
            .join("exports/patches/patches-render.png")
            .is_file()
    );
    assert_eq!(
        std::fs::read(&built).unwrap(),
        before,
        "the build's picture"
    );
    // A .jpg or a folder is refused before anything is built or written.
    for (out_flag, words) in [
        ("x.jpg", ["--out", "ending in .png"]),
        ("exports", ["--out", "is a folder"]),
    ] {
        let out = halo4d(&["render", &file, "--quiet", "--out", out_flag], dir.path());
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{err}");
        for w in words {
            assert!(err.contains(w), "`{w}` not in {err}");
        }
    }
    assert!(!dir.path().join("x.jpg").exists());
}

#[test]
fn slice_draws_the_spun_trefoils_square_knot_and_checks_its_critical_levels() {
    // Along the spinning plane's w (the default scene's `slicing`) the spun trefoil's
    // middle slice is the arc and its mirror image: the square knot, one curve with six
    // crossings; either side of it two curves, and one curve nearest the extremes.
    let dir = tempfile::tempdir().unwrap();
    let out = halo4d(&["slice", "--film", "12", "--out", "m", "-q"], dir.path());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("2 births, 2 saddles, 2 deaths (χ = 2)"),
        "{err}"
    );
    let m = dir.path().join("m");
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(m.join("motion.json")).unwrap()).unwrap();
    let surface = &json["surfaces"][0];
    assert_eq!(json["verified"], true);
    assert_eq!(
        surface["components"],
        serde_json::json!([0, 1, 2, 1, 2, 1, 0])
    );
    let stills: Vec<(u64, u64)> = surface["stills"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| {
            (
                s["curves"].as_u64().unwrap(),
                s["crossings"].as_u64().unwrap(),
            )
        })
        .collect();
    assert_eq!(stills, [(1, 0), (2, 4), (1, 6), (2, 4), (1, 0)]);
    for f in [
        "spun_trefoil-motion.png",
        "spun_trefoil-motion.svg",
        "spun_trefoil-still-02.ply",
    ] {
        assert!(m.join(f).is_file(), "{f}");
    }
    // The film: 12 frames through the levels, each recorded, an animated PNG of 12 frames.
    let film = surface["film"].as_array().unwrap();
    assert_eq!(film.len(), 12);
    let decoder = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(m.join("spun_trefoil-film.png")).unwrap(),
    ));
    let reader = decoder.read_info().unwrap();
    assert_eq!(
        reader.info().animation_control.map(|a| a.num_frames),
        Some(12)
    );
    let counts: Vec<u64> = film.iter().map(|f| f["curves"].as_u64().unwrap()).collect();
    assert_eq!(counts.first(), Some(&1));
    assert!(counts.contains(&2), "{counts:?}");
    let svg = std::fs::read_to_string(m.join("spun_trefoil-motion.svg")).unwrap();
    assert!(svg.contains("1 curve, 6 crossings") && svg.ends_with("</svg>\n"));
    // The flags override the scene's: along the view's w (the direction without either),
    // another motion picture, with its own count of critical points, still χ = 2.
    let out = halo4d(
        &[
            "slice",
            "--direction",
            "0.1,0.2,0.3,0.9",
            "--levels",
            "0",
            "--out",
            "n",
            "-q",
        ],
        dir.path(),
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        !err.contains("2 births, 2 saddles, 2 deaths") && err.contains("(χ = 2)"),
        "{err}"
    );
}

#[test]
fn slice_fails_a_degenerate_direction_until_it_is_tilted_and_refuses_bad_flags() {
    let dir = tempfile::tempdir().unwrap();
    let scene = fixture("scenes/flat-torus.json");
    let scene = scene.to_str().unwrap();
    // Along w the flat torus's height has critical circles: exit 3, saying what to do.
    let out = halo4d(
        &["slice", scene, "--direction", "0,0,0,1", "--out", "a", "-q"],
        dir.path(),
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{err}");
    assert!(
        err.contains("FAILED") && err.contains("degenerate"),
        "{err}"
    );
    let out = halo4d(
        &[
            "slice",
            scene,
            "--direction",
            "0,0,0,1",
            "--perturb",
            "2",
            "--out",
            "b",
            "-q",
        ],
        dir.path(),
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("1 births, 2 saddles, 1 deaths (χ = 0)"),
        "{err}"
    );
    for (flags, expected) in [
        (
            &["--direction", "0,0,0,0"][..],
            "--direction: must be a nonzero",
        ),
        (&["--direction", "1,2"][..], "2 numbers; give four"),
        (&["--direction", "1,x,0,0"][..], "`x` is not a number"),
        (&["--perturb", "45"][..], "--perturb"),
        (&["--levels", "100"][..], "--levels"),
        (&["--film", "5000"][..], "--film"),
    ] {
        let mut args = vec!["slice", scene, "--out", "c", "-q"];
        args.extend_from_slice(flags);
        let out = halo4d(&args, dir.path());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            !out.status.success() && err.contains(expected),
            "{flags:?}: {err}"
        );
        assert!(!dir.path().join("c").exists(), "{flags:?} wrote files");
    }
    // A scene's own `slicing` is checked with the scene, naming its field.
    let bad = dir.path().join("bad.json");
    let text = std::fs::read_to_string(fixture("scenes/flat-torus.json")).unwrap();
    let mut json: serde_json::Value = serde_json::from_str(&text).unwrap();
    json["slicing"] = serde_json::json!({ "perturb": 20 });
    std::fs::write(&bad, json.to_string()).unwrap();
    let out = halo4d(
        &["slice", bad.to_str().unwrap(), "--out", "c", "-q"],
        dir.path(),
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("slicing.perturb: must be 0 to 10"), "{err}");
}
