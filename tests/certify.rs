//! The certified check of any tetrahedral mesh (`certify`, `halo4d check` on meshes without
//! halo4d's layout): the fixtures of Gmsh's meshes with planted faults get the verdict their
//! README names, faults planted exactly in Kuhn's cube are each caught, named and marked
//! on the right tetrahedra, and a clean mesh passes at any scale.

use crate::common::{failure_names, fixture, halo4d};
use halo4d::certify::{Certificate, Convention, Fault, certify, kuhn_cube};

/// The names of a certificate's failures.
fn names(c: &Certificate) -> Vec<String> {
    failure_names(&c.failures())
}

/// The tetrahedra with fault bit `bit`.
fn marked(c: &Certificate, bit: u32) -> Vec<usize> {
    (0..c.faults.len())
        .filter(|&i| c.faults[i] & bit != 0)
        .collect()
}

/// The positions `p` moved by `by`.
fn translated(p: &[[f64; 3]], by: [f64; 3]) -> Vec<[f64; 3]> {
    p.iter()
        .map(|q| [q[0] + by[0], q[1] + by[1], q[2] + by[2]])
        .collect()
}

/// Two meshes in one: the second's vertex indices after the first's.
fn joined(
    (p1, t1): (Vec<[f64; 3]>, Vec<[u32; 4]>),
    (p2, t2): (Vec<[f64; 3]>, Vec<[u32; 4]>),
) -> (Vec<[f64; 3]>, Vec<[u32; 4]>) {
    let n = p1.len() as u32;
    let mut p = p1;
    p.extend(p2);
    let mut t = t1;
    t.extend(t2.iter().map(|q| q.map(|i| i + n)));
    (p, t)
}

/// A tetrahedron of the cube none of whose vertices is on its boundary.
fn interior(p: &[[f64; 3]], t: &[[u32; 4]], n: f64) -> usize {
    let inside = |i: u32| p[i as usize].iter().all(|&x| x > 0.0 && x < n);
    t.iter()
        .position(|q| q.iter().all(|&i| inside(i)))
        .expect("an interior tetrahedron")
}

#[test]
fn every_fixture_mesh_gets_the_verdict_its_readme_names() {
    let dir = fixture("tetmeshes/faults");
    let readme = std::fs::read_to_string(dir.join("README.md")).unwrap();
    let mut rows = 0;
    for line in readme
        .lines()
        .filter(|l| l.starts_with("| ") && l.contains(".vtk"))
    {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        let (file, tets, verdict) = (cells[1], cells[2], cells[3]);
        let checked = halo4d::check_file(&dir.join(file)).unwrap();
        let c = checked
            .certificate
            .as_ref()
            .expect("a plain mesh is certified");
        assert_eq!(c.stats.tets.to_string(), tets, "{file}");
        let expected: Vec<String> = verdict
            .strip_prefix("fails: ")
            .map(|names| {
                names
                    .split(", ")
                    .map(|n| n.trim_matches('`').to_string())
                    .collect()
            })
            .unwrap_or_default();
        let found = names(c);
        if expected.is_empty() {
            assert!(verdict.starts_with("passes"), "{file}: {verdict}");
            assert!(found.is_empty(), "{file} must pass: {found:?}");
        } else {
            for name in &expected {
                assert!(found.contains(name), "{file}: {name} not among {found:?}");
            }
        }
        // `meshes[0].certificate.boundary.cavities == 1` and the like, read off the JSON.
        if let Some((path, value)) = verdict
            .split('`')
            .find(|s| s.starts_with("meshes"))
            .and_then(|s| s.split_once(" == "))
        {
            let pointer = format!("/{}", path.replace(['[', '.'], "/").replace(']', ""));
            let json = checked.json();
            let got = json
                .pointer(&pointer)
                .unwrap_or_else(|| panic!("{pointer}"));
            assert_eq!(got.to_string(), value, "{file}: {path}");
        }
        rows += 1;
    }
    assert!(rows >= 16, "{rows} rows in the README");
}

#[test]
fn faults_planted_exactly_in_kuhns_cube_are_caught_named_and_marked() {
    let (p, t) = kuhn_cube(4);
    let clean = certify(&p, &t);
    assert!(clean.failures().is_empty(), "{:?}", clean.failures());
    assert_eq!(clean.boundary.windings, [Some(1)]);
    let i = interior(&p, &t, 4.0);

    // One tetrahedron flipped: inverted, that one marked.
    let mut flipped = t.clone();
    flipped[i].swap(0, 1);
    let c = certify(&p, &flipped);
    assert_eq!(names(&c)[0], "inverted");
    assert_eq!(marked(&c, Fault::INVERTED), [i]);

    // Every tetrahedron flipped: the other convention, and valid in it.
    let all: Vec<[u32; 4]> = t.iter().map(|q| [q[1], q[0], q[2], q[3]]).collect();
    let c = certify(&p, &all);
    assert_eq!(c.convention, Convention::Reversed);
    assert!(c.failures().is_empty(), "{:?}", c.failures());

    // One listed twice: both copies marked.
    let mut twice = t.clone();
    twice.push(t[i]);
    let c = certify(&p, &twice);
    assert!(names(&c).contains(&"duplicate_tets".to_string()));
    assert_eq!(marked(&c, Fault::DUPLICATE), [i, t.len()]);

    // One removed from the inside: not a fault, a cavity whose four neighbours are marked.
    let mut cavity = t.clone();
    cavity.remove(i);
    let c = certify(&p, &cavity);
    assert!(c.failures().is_empty(), "{:?}", c.failures());
    assert_eq!((c.boundary.components, c.boundary.cavities), (2, 1));
    assert_eq!(c.boundary.windings, [Some(1), Some(1)]);
    assert_eq!(marked(&c, Fault::CAVITY).len(), 4);

    // A vertex exactly on a face (a + b + 2c) / 4, the neighbour across it keeping the
    // face whole.
    let [a, b, cc, d] = t[i];
    let at = |k: u32| p[k as usize];
    let h = [0, 1, 2].map(|k| (at(a)[k] + at(b)[k] + 2.0 * at(cc)[k]) / 4.0);
    let mut hp = p.clone();
    hp.push(h);
    let hv = p.len() as u32;
    let mut ht: Vec<[u32; 4]> = t.clone();
    ht.remove(i);
    // Each part keeps the orientation of (a, b, c, d) with one corner of the face moved to h.
    ht.extend([[a, b, hv, d], [hv, b, cc, d], [a, hv, cc, d]]);
    let c = certify(&hp, &ht);
    assert_eq!(c.stats.inverted + c.stats.flat, 0);
    assert!(
        names(&c).contains(&"hanging_vertices".to_string()),
        "{:?}",
        c.failures()
    );
    let neighbour = t
        .iter()
        .position(|q| q != &t[i] && [a, b, cc].iter().all(|v| q.contains(v)))
        .unwrap();
    let neighbour = if neighbour > i {
        neighbour - 1
    } else {
        neighbour
    };
    assert!(marked(&c, Fault::HANGING).contains(&neighbour));

    // A tetrahedron outside touching the cube at a corner, then along an edge.
    let corner = |extra: Vec<[f64; 3]>, shared: &[u32]| {
        let mut q = p.clone();
        let n = q.len() as u32;
        q.extend(extra);
        let mut tet: Vec<u32> = shared.to_vec();
        tet.extend(n..n + (4 - shared.len() as u32));
        let mut tt = t.clone();
        let mut tet: [u32; 4] = tet.try_into().unwrap();
        let pos = tet.map(|k| q[k as usize]);
        let c3 = |x: [f64; 3]| robust::Coord3D {
            x: x[0],
            y: x[1],
            z: x[2],
        };
        if robust::orient3d(c3(pos[0]), c3(pos[1]), c3(pos[2]), c3(pos[3])) < 0.0 {
            tet.swap(0, 1);
        }
        tt.push(tet);
        certify(&q, &tt)
    };
    let top = (p.len() - 1) as u32; // (4, 4, 4)
    let c = corner(
        vec![[5.0, 4.5, 4.5], [4.5, 5.0, 4.5], [4.5, 4.5, 5.0]],
        &[top],
    );
    assert_eq!(names(&c), ["nonmanifold_vertices"]);
    assert!(marked(&c, Fault::NONMANIFOLD).contains(&t.len()));
    let below = top - 1; // (3, 4, 4): the edge along x on the top back edge of the cube
    let c = corner(vec![[3.5, 5.0, 5.0], [3.5, 5.0, 6.0]], &[below, top]);
    assert!(
        names(&c).contains(&"nonmanifold_edges".to_string()),
        "{:?}",
        c.failures()
    );

    // No tetrahedra at all: vacuously valid, but not what anyone meant to check.
    assert_eq!(names(&certify(&p, &[])), ["tetrahedra"]);

    // Two cubes apart pass; overlapping, their boundaries cross and the overlap is wound
    // twice; one inside the other, the inner one is wound twice.
    let far = joined(kuhn_cube(4), (translated(&p, [10.0, 0.0, 0.0]), t.clone()));
    let c = certify(&far.0, &far.1);
    assert!(c.failures().is_empty(), "{:?}", c.failures());
    assert_eq!((c.boundary.components, c.boundary.cavities), (2, 0));
    let over = joined(kuhn_cube(4), (translated(&p, [2.5, 0.5, 0.5]), t.clone()));
    let c = certify(&over.0, &over.1);
    let found = names(&c);
    assert!(
        found.contains(&"self_intersections".to_string()),
        "{found:?}"
    );
    let (small_p, small_t) = kuhn_cube(1);
    let nested = joined(
        kuhn_cube(4),
        (translated(&small_p, [1.5, 1.5, 1.5]), small_t),
    );
    let c = certify(&nested.0, &nested.1);
    assert_eq!(names(&c), ["wrong_winding"]);
    assert_eq!(c.boundary.windings, [Some(1), Some(2)]);
    assert_eq!(
        marked(&c, Fault::WINDING),
        (t.len()..t.len() + 6).collect::<Vec<_>>()
    );
}

#[test]
fn a_mesh_scaled_by_powers_of_two_gets_the_same_certificate_and_1e150_is_still_exact() {
    let (p, t) = kuhn_cube(3);
    let mut faulty = t.clone();
    faulty[40].swap(2, 3);
    for tets in [&t, &faulty] {
        let reference = certify(&p, tets);
        for e in [-1000, -400, 400, 1000] {
            let s = 2f64.powi(e);
            let scaled: Vec<[f64; 3]> = p.iter().map(|q| q.map(|x| x * s)).collect();
            let c = certify(&scaled, tets);
            assert_eq!(c.failures(), reference.failures(), "2^{e}");
            assert_eq!(c.boundary, reference.boundary, "2^{e}");
            assert_eq!(c.faults, reference.faults, "2^{e}");
        }
        for s in [1e150, 1e-150] {
            let scaled: Vec<[f64; 3]> = p.iter().map(|q| q.map(|x| x * s)).collect();
            assert_eq!(names(&certify(&scaled, tets)), names(&reference), "{s}");
        }
    }
}

#[test]
fn a_volume_beyond_an_f64_is_given_by_its_logarithm() {
    // Kuhn's cube scaled by 2^1000: its volume times 2^3000 overflows, its logarithm does
    // not.
    let (p, t) = kuhn_cube(3);
    let at_one = certify(&p, &t).stats;
    assert!((at_one.volume_log10 - at_one.volume.log10()).abs() < 1e-12);
    let s = 2f64.powi(1000);
    let scaled: Vec<[f64; 3]> = p.iter().map(|q| q.map(|x| x * s)).collect();
    let c = certify(&scaled, &t);
    assert!(c.failures().is_empty(), "{:?}", c.failures());
    assert!(c.stats.volume.is_infinite());
    let want = at_one.volume.log10() + 3000.0 * std::f64::consts::LOG10_2;
    assert!(
        (c.stats.volume_log10 - want).abs() < 1e-9,
        "{}",
        c.stats.volume_log10
    );
    // The command prints the decimal: one tetrahedron with legs of 1e300 encloses 1e900 / 6.
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("big.vtk");
    std::fs::write(
        &file,
        "# vtk DataFile Version 4.2\nbig\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 4 double\n0 0 0\n1e300 0 0\n0 1e300 0\n0 0 1e300\nCELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\n",
    )
    .unwrap();
    let o = halo4d(&["check", file.to_str().unwrap()], dir.path());
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{out}");
    assert!(out.contains("1.667e899 (beyond an f64)"), "{out}");
}

#[test]
fn check_prints_json_and_marks_each_faulty_tetrahedron_in_a_vtu() {
    let dir = tempfile::tempdir().unwrap();
    let faults = fixture("tetmeshes/faults");
    let file = faults.join("nested-balls.vtk");
    let out = halo4d(&["check", file.to_str().unwrap(), "--json"], dir.path());
    assert_eq!(out.status.code(), Some(1));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["passes"], false);
    assert_eq!(
        json["meshes"][0]["certificate"]["boundary"]["windings"][1],
        2
    );

    let mark = dir.path().join("marked.vtu");
    let out = halo4d(
        &[
            "check",
            file.to_str().unwrap(),
            "--mark",
            mark.to_str().unwrap(),
        ],
        dir.path(),
    );
    assert_eq!(out.status.code(), Some(1));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("wrong winding"), "{text}");
    let bytes = std::fs::read(&mark).unwrap();
    assert!(bytes.starts_with(b"<?xml") && bytes.ends_with(b"</VTKFile>\n"));
    // The marked file reads back as the same mesh, with the same verdict and faults.
    let original = halo4d::check_file(&file).unwrap();
    let again = halo4d::check_file(&mark).unwrap();
    assert_eq!(
        again.mesh.as_ref().unwrap().tets,
        original.mesh.as_ref().unwrap().tets
    );
    assert_eq!(again.failures(), original.failures());
    let marks = |c: &halo4d::Checked| c.certificate.as_ref().unwrap().faults.clone();
    assert_eq!(marks(&again), marks(&original));

    // A clean mesh passes and says why; --mark wants a .vtu, and a mesh of its own kind.
    let out = halo4d(
        &["check", faults.join("cube.vtk").to_str().unwrap()],
        dir.path(),
    );
    assert_eq!(out.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&out.stdout).contains("ok: a valid tetrahedralization"));
    let out = halo4d(
        &["check", file.to_str().unwrap(), "--mark", "x.vtk"],
        dir.path(),
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("give a .vtu file"));
}

#[test]
fn a_soup_of_ten_thousand_separate_tetrahedra_is_ten_thousand_components() {
    // Every component's winding number is a few BVH queries, not a pass over every face:
    // a pass each would be 10^4 components times 4 10^4 faces.
    let corner = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let (mut p, mut t) = (Vec::new(), Vec::new());
    for i in 0..10_000u32 {
        let at = [(i % 100) as f64 * 2.0, (i / 100) as f64 * 2.0, 0.0];
        p.extend(
            corner
                .iter()
                .map(|q| [q[0] + at[0], q[1] + at[1], q[2] + at[2]]),
        );
        // (0, 1, 2, 3) turns clockwise seen from the corner: halo4d's positive order.
        t.push([4 * i, 4 * i + 2, 4 * i + 1, 4 * i + 3]);
    }
    let c = certify(&p, &t);
    assert!(c.failures().is_empty(), "{:?}", c.failures());
    assert_eq!(c.convention, Convention::Positive);
    assert_eq!((c.boundary.components, c.boundary.cavities), (10_000, 0));
    assert!(c.boundary.windings.iter().all(|&w| w == Some(1)));
}

#[test]
fn a_valid_mesh_gets_the_same_certificate_wherever_it_stands() {
    // Integer coordinates moved by whole numbers (and halves) stay exact, so every mesh
    // below is the cube itself, moved: its verdict, boundary, faults and volume are the
    // cube's. The boundary's volume summed from the origin cancelled 300 units away.
    let (p, t) = kuhn_cube(4);
    let mut faulty = t.clone();
    faulty[40].swap(2, 3);
    for tets in [&t, &faulty] {
        let reference = certify(&p, tets);
        for by in [
            [300.0, 300.0, 300.0],
            [1e6, 1e6, 1e6],
            [-1e6 - 0.5, 2e9, 0.25],
            [2f64.powi(50), -3e15, 7e14],
        ] {
            let c = certify(&translated(&p, by), tets);
            assert_eq!(c.failures(), reference.failures(), "{by:?}");
            assert_eq!(c.boundary, reference.boundary, "{by:?}");
            assert_eq!(c.faults, reference.faults, "{by:?}");
            assert!(
                (c.stats.volume - 64.0).abs() < 1e-9 && c.stats.volume_defect < 1e-12,
                "{by:?}: volume {} defect {}",
                c.stats.volume,
                c.stats.volume_defect
            );
        }
    }
}

#[test]
fn vertices_no_tetrahedron_uses_take_no_part_in_the_certificate() {
    // One vertex far away that no cell names made every tetrahedron undecidable (1e80) or
    // every face one BVH box (1e308).
    let (p, t) = kuhn_cube(4);
    let reference = certify(&p, &t);
    assert!(reference.failures().is_empty());
    for extra in [[1e80, 0.0, 0.0], [1e308, -1e308, 1e308], [1e-300, 0.0, 0.0]] {
        let mut q = p.clone();
        q.insert(0, extra);
        let shifted: Vec<[u32; 4]> = t.iter().map(|x| x.map(|i| i + 1)).collect();
        let c = certify(&q, &shifted);
        assert!(c.failures().is_empty(), "{extra:?}: {:?}", c.failures());
        assert_eq!(c.boundary, reference.boundary, "{extra:?}");
        assert_eq!(c.stats.volume, reference.stats.volume, "{extra:?}");
    }
}

#[test]
fn tetrahedra_beyond_the_exact_range_are_undecidable_and_nothing_else_is_claimed_of_them() {
    // The cube beside one tetrahedron 1e100 times its size: the cube's coordinates are
    // below what the exact predicates can take against the largest, so its tetrahedra are
    // undecidable, said once as a count; no hanging vertex, crossing or misoriented edge
    // is made up from the rounded coordinates.
    let far = (
        vec![
            [1e100, 0.0, 0.0],
            [2e100, 0.0, 0.0],
            [1e100, 1e100, 0.0],
            [1e100, 0.0, 1e100],
        ],
        vec![[0, 2, 1, 3]],
    );
    let (p, t) = joined(kuhn_cube(3), far);
    let c = certify(&p, &t);
    let b = &c.boundary;
    assert_eq!(c.stats.undecidable, 162);
    assert_eq!(
        (
            b.hanging_vertices,
            b.self_intersections,
            b.misoriented_edges,
            b.nonmanifold_edges
        ),
        (0, 0, 0, 0),
        "{b:?}"
    );
    assert_eq!(b.undecided_faces, 108);
    assert!(c.stats.volume.is_finite() && c.stats.volume > 0.0);
    assert_eq!(
        names(&c),
        ["undecidable", "undecided_windings"],
        "{:?}",
        c.failures()
    );
}

/// Kuhn's cube [0, 4]^3 as a `.pvtu` of two pieces (the cubes below x = 2, and the rest),
/// each piece with its own points, in `dir`; `shift` moves the second piece's points on the
/// cut along x. Returns the `.pvtu`'s path.
fn two_pieces(dir: &std::path::Path, shift: f64) -> std::path::PathBuf {
    use halo4d::export::write_tetrahedra_vtu;
    use halo4d::internals::file_order;
    let (p, t) = kuhn_cube(4);
    for (k, below) in [(0, true), (1, false)] {
        let tets: Vec<[u32; 4]> = t
            .iter()
            .filter(|q| (q.iter().map(|&i| p[i as usize][0]).sum::<f64>() < 8.0) == below)
            .copied()
            .collect();
        let mut used: Vec<u32> = tets.iter().flatten().copied().collect();
        used.sort_unstable();
        used.dedup();
        let local = |i: u32| used.binary_search(&i).unwrap() as u32;
        let points: Vec<[f64; 3]> = used
            .iter()
            .map(|&i| {
                let mut x = p[i as usize];
                if k == 1 && x[0] == 2.0 {
                    x[0] += shift;
                }
                x
            })
            .collect();
        let tets: Vec<[u32; 4]> = tets.iter().map(|q| file_order(q.map(local))).collect();
        write_tetrahedra_vtu(&dir.join(format!("cube_{k}.vtu")), &points, &tets, &[], &[]).unwrap();
    }
    let pvtu = dir.join("cube.pvtu");
    std::fs::write(
        &pvtu,
        r#"<?xml version="1.0"?>
<VTKFile type="PUnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">
  <PUnstructuredGrid GhostLevel="0">
    <PPoints><PDataArray type="Float64" NumberOfComponents="3"/></PPoints>
    <Piece Source="cube_0.vtu"/>
    <Piece Source="cube_1.vtu"/>
  </PUnstructuredGrid>
</VTKFile>
"#,
    )
    .unwrap();
    pvtu
}

#[test]
fn a_partitioned_mesh_is_certified_as_one_and_a_fault_between_pieces_names_both() {
    let dir = tempfile::tempdir().unwrap();
    let whole = halo4d::check_file(&two_pieces(dir.path(), 0.0)).unwrap();
    assert!(whole.failures().is_empty(), "{:?}", whole.failures());
    let c = whole.certificate.as_ref().unwrap();
    // The points on the cut welded: the cube's 125, one boundary component.
    assert_eq!((c.stats.vertices, c.stats.tets), (125, 384));
    assert_eq!(c.boundary.components, 1);
    let pieces = whole.pieces();
    assert_eq!(
        pieces
            .iter()
            .map(|p| (p.file.as_str(), p.tets))
            .collect::<Vec<_>>(),
        [("cube_0.vtu", 192), ("cube_1.vtu", 192)]
    );
    assert!(pieces.iter().all(|p| p.faulty == 0));

    // The second piece's cut moved into the first: the pieces overlap, and both are named.
    let overlap = halo4d::check_file(&two_pieces(dir.path(), -0.25)).unwrap();
    assert!(!overlap.failures().is_empty());
    let pieces = overlap.pieces();
    assert!(pieces.iter().all(|p| p.faulty > 0), "{pieces:?}");
    let text = overlap.text();
    for file in ["cube_0.vtu", "cube_1.vtu"] {
        assert!(text.contains(&format!("piece {file}: ")), "{text}");
    }
}

#[test]
fn the_fault_bits_are_declared_once_and_the_readme_and_the_help_list_them() {
    // The bits are the powers of two in order, each named once.
    for (k, f) in Fault::ALL.iter().enumerate() {
        assert_eq!(f.bit, 1 << k, "{}", f.name);
    }
    let names: std::collections::BTreeSet<&str> = Fault::ALL.iter().map(|f| f.name).collect();
    assert_eq!(names.len(), Fault::ALL.len());
    assert_eq!(Fault::NONCONFORMING, Fault::ALL[12].bit);
    let readme =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/README.md")).unwrap();
    let table = Fault::table();
    assert!(
        readme.contains(&table),
        "the README's table of fault bits is not the code's; it should read:\n{table}"
    );
    // `halo4d check --help` lists every bit.
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_halo4d"))
        .args(["check", "--help"])
        .output()
        .unwrap();
    let help = String::from_utf8_lossy(&out.stdout)
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ");
    assert!(help.contains(&Fault::legend()), "{help}");
}
