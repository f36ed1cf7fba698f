//! `halo4d check`: what a build wrote, checked again from the files alone.
//!
//! Takes: a `.glb` or legacy `.vtk` file of halos, or any tetrahedral mesh another program
//! wrote ([`check_file`]; a mesh without halo4d's layout is certified, [`certify`]), or a
//! build's output folder with its one scene `.glb` ([`check_dir`]). Gives: [`Checked`], each
//! halo's [`CheckStats`] (a plain mesh's [`Certificate`]) and, for a folder, the
//! intersection curves recomputed from the file's surfaces and the halos' [`Verification`]
//! against them; as text ([`Checked::text`]) or JSON ([`Checked::json`]), and a plain
//! mesh's faults per tetrahedron as a `.vtu` ([`Checked::write_marks`]).
//! Guarantees: the verdict ([`Checked::failures`]) is a build's ([`crate::Built::failures`]),
//! from the same library functions: [`CheckStats::verdict`], [`CurvesReport::failures`],
//! [`Verification::failures`].

use crate::certify::{Certificate, Fault, certify_cells};
use crate::check::{CheckStats, HALO_ONLY, check};
use crate::convention::file_order;
use crate::export::{CellValues, write_tetrahedra_vtu};
use crate::import::{
    self, FileTetrahedra, ImportError, ImportedHalo, ImportedScene, PlainTetrahedra,
};
use crate::intersect::{self, Curves, CurvesReport};
use crate::verify::{self, Verification};
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// What `halo4d check` found.
#[derive(Clone, Debug)]
pub struct Checked {
    /// The file read.
    pub file: PathBuf,
    /// The scene's name, when the file records it.
    pub scene: Option<String>,
    /// Each halo's name and the checker's statistics (for a file without halo4d's layout,
    /// its tetrahedra's, from [`crate::certify`]).
    pub halos: Vec<(String, CheckStats)>,
    /// For a mesh without halo4d's layout: why it is not read as a halo. Its tetrahedra
    /// are certified instead ([`Self::certificate`]); the halo's own checks (offset faces,
    /// quads, surface faces) cannot be made.
    pub plain: Option<String>,
    /// For a mesh without halo4d's layout: what [`crate::certify`] found.
    pub certificate: Option<Certificate>,
    /// For a mesh without halo4d's layout: its tetrahedra as read, for
    /// [`Self::write_marks`].
    pub mesh: Option<PlainTetrahedra>,
    /// For a folder: the curves recomputed from the file's surfaces, and the halos
    /// verified against them.
    pub verification: Option<(CurvesReport, Verification)>,
    /// The halos whose files lack what a check of theirs needs: nothing is claimed of what
    /// could not be checked.
    pub unchecked: Vec<Unchecked>,
}

/// A halo whose file lacks what the check of its coverage of the surface needs (the surface's
/// triangles: without them, a halo with prisms cut away reads as a valid shell of what is
/// left). The checks that need no more are made; the coverage is reported unchecked, never
/// passed. (Certifying its tetrahedra as a plain mesh would not see the coverage either,
/// and would fail valid halos: a halo's boundary meets itself wherever its surface does.)
#[derive(Clone, Debug)]
pub struct Unchecked {
    /// The halo.
    pub halo: String,
    /// What is not checked, and why.
    pub why: String,
}

/// A piece of a partitioned mesh and the faults of its tetrahedra ([`Checked::pieces`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Piece {
    /// Its file, as the `.pvtu` names it.
    pub file: String,
    /// Its cells: its tetrahedra, and a mixed mesh's other cells.
    pub tets: usize,
    /// Those with a fault.
    pub faulty: usize,
    /// How many have each fault, by the fault's name ([`Fault::ALL`]), the faults none
    /// has left out.
    pub faults: Vec<(&'static str, usize)>,
}

/// Why `halo4d check` could not read what it was given.
#[derive(Debug, thiserror::Error)]
pub enum InspectError {
    /// The folder holds no single scene `.glb`.
    #[error("{}: {message}", dir.display())]
    Folder {
        /// The folder.
        dir: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// The file could not be read as halos.
    #[error("{}: {source}", file.display())]
    File {
        /// The file.
        file: PathBuf,
        /// Why.
        source: ImportError,
    },
}

/// Checks the halos of a `.glb` or `.vtk` file with the independent checker.
pub fn check_file(file: &Path) -> Result<Checked, InspectError> {
    let read = import::read(file).map_err(|source| InspectError::File {
        file: file.to_path_buf(),
        source,
    })?;
    let checked = Checked {
        file: file.to_path_buf(),
        scene: None,
        halos: Vec::new(),
        plain: None,
        certificate: None,
        mesh: None,
        verification: None,
        unchecked: Vec::new(),
    };
    Ok(match read {
        FileTetrahedra::Halos(halos) => {
            let (halos, unchecked) = check_halos(halos.iter());
            Checked {
                halos,
                unchecked,
                ..checked
            }
        }
        FileTetrahedra::Plain(mesh) => check_mesh(file, mesh),
    })
}

/// Certifies a tetrahedral mesh without halo4d's layout, read from `file` or given in
/// memory ([`PlainTetrahedra::from_arrays`]; `file` then names where it came from): what
/// [`check_file`] gives for such a file.
pub fn check_mesh(file: &Path, mesh: PlainTetrahedra) -> Checked {
    let certificate = certify_cells(&mesh.positions, &mesh.tets, &mesh.solids);
    Checked {
        file: file.to_path_buf(),
        scene: None,
        halos: vec![(mesh.name.clone(), certificate.stats)],
        plain: Some(mesh.why.clone()),
        certificate: Some(certificate),
        mesh: Some(mesh),
        verification: None,
        unchecked: Vec::new(),
    }
}

/// Checks a build's output folder: reads its one `.glb`, runs the checker on each halo,
/// recomputes the intersection curves of the file's surfaces and verifies the halos against
/// them.
pub fn check_dir(dir: &Path) -> Result<Checked, InspectError> {
    let file = scene_glb(dir).map_err(|message| InspectError::Folder {
        dir: dir.to_path_buf(),
        message,
    })?;
    let scene = std::fs::read(&file)
        .map_err(ImportError::from)
        .and_then(|bytes| import::read_scene_glb(&bytes))
        .map_err(|source| InspectError::File {
            file: file.clone(),
            source,
        })?;
    let (halos, unchecked) = check_halos(scene.surfaces.iter().filter_map(|s| s.halo.as_ref()));
    let (mut curves, verification) = verify_scene(&scene);
    curves.report.certified = recertify(&scene);
    Ok(Checked {
        file,
        scene: scene.name.clone(),
        halos,
        plain: None,
        certificate: None,
        mesh: None,
        verification: Some((curves.report, verification)),
        unchecked,
    })
}

/// Recomputes the intersection curves of a scene read from its `.glb` and verifies its
/// halos against them, as a build does ([`crate::pipeline::Sampled::build`]).
pub fn verify_scene(scene: &ImportedScene) -> (Curves, Verification) {
    let curves = intersect::curves(&scene.parts(&Curves::default()).sheets());
    let verification = verify::verify(&scene.parts(&curves));
    (curves, verification)
}

/// The certificate of the double curves of the scene recorded in the file, derived again
/// from its analytic surfaces and view, when that scene asked for one (`curves.certify`).
fn recertify(scene: &ImportedScene) -> Option<intersect::certified::Certificate> {
    let recorded: crate::scene::Scene = serde_json::from_value(scene.scene.clone()?).ok()?;
    if !recorded.curves.certify {
        return None;
    }
    let surfaces: Vec<_> = recorded
        .surfaces
        .iter()
        .map(|s| s.surface.parametric())
        .collect();
    Some(intersect::certified::certify(&surfaces, &recorded.view))
}

/// Each halo's checker statistics; and the halos whose files do not give the surface's
/// triangles, whose coverage of the surface is therefore unchecked.
fn check_halos<'a>(
    halos: impl Iterator<Item = &'a ImportedHalo>,
) -> (Vec<(String, CheckStats)>, Vec<Unchecked>) {
    let mut stats = Vec::new();
    let mut unchecked = Vec::new();
    for h in halos {
        stats.push((h.name.clone(), check(&h.mesh)));
        if h.mesh.surface_triangles.is_empty() {
            unchecked.push(Unchecked {
                halo: h.name.clone(),
                why: "the file does not give the surface's triangles (`surface_triangles`; an earlier halo4d wrote it), and read off the boundary alone a halo with prisms cut away is a valid shell of what is left. Build the scene again with this halo4d to check it".into(),
            });
        }
    }
    (stats, unchecked)
}

impl Checked {
    /// The verdict: what keeps the file from passing, empty when it passes. Every halo
    /// passes the checker; for a folder also every curve is resolved and the verification
    /// finds no wrong curve sample and no spuriously hidden surface sample.
    pub fn failures(&self) -> Vec<String> {
        if let Some(certificate) = &self.certificate {
            return certificate.failures();
        }
        let mut out: Vec<String> = self
            .halos
            .iter()
            .filter_map(|(name, stats)| stats.verdict(name))
            .collect();
        if let Some((curves, verification)) = &self.verification {
            out.extend(curves.failures());
            out.extend(verification.failures());
        }
        out
    }

    /// What `halo4d check` prints: the checker's table (a row per statistic, a column per
    /// halo); for a folder the scene, the curves and the verification's counts; a `FAILED`
    /// line per failure, or an `ok` line.
    pub fn text(&self) -> String {
        let mut out = String::new();
        if self.verification.is_some() {
            match &self.scene {
                Some(name) => out += &format!("scene {name}: {}\n", self.file.display()),
                None => out += &format!("{}\n", self.file.display()),
            }
        }
        if let Some(why) = &self.plain {
            out += &format!(
                "not a halo: {why}. Certified as a tetrahedral mesh: its cells, how they meet, its boundary and that no two overlap; not checked: the halo's offset faces, quads and surface faces\n"
            );
        }
        if self.halos.is_empty() {
            out += "no halo in the file\n";
        } else {
            out += &stats_table(&self.halos, self.plain.is_some());
        }
        if let Some(c) = &self.certificate {
            out += &certificate_text(c);
        }
        let mesh_is_mixed = self.certificate.as_ref().is_some_and(|c| c.cells.is_some());
        for p in self.pieces().iter().filter(|p| p.faulty > 0) {
            let faults: Vec<String> = p.faults.iter().map(|(f, n)| format!("{n} {f}")).collect();
            out += &format!(
                "piece {}: {} of its {} {} with a fault ({})\n",
                p.file,
                p.faulty,
                p.tets,
                if mesh_is_mixed { "cells" } else { "tetrahedra" },
                faults.join(", ")
            );
        }
        for u in &self.unchecked {
            out += &format!(
                "halo {}: its coverage of the surface is NOT checked: {}\n",
                u.halo, u.why
            );
        }
        if let Some((curves, v)) = &self.verification {
            out += &format!("\n{}\n", curves.summary());
            let rows = v.rows();
            let width = rows.iter().map(|(k, _)| k.len()).max().unwrap_or(0);
            out += &format!("{:<width$}  {:>9}\n", "halo verification", "samples");
            for (k, n) in rows {
                out += &format!("{k:<width$}  {n:>9}\n");
            }
        }
        let failures = self.failures();
        for f in &failures {
            out += &format!("FAILED {f}\n");
        }
        if let (true, Some(c)) = (failures.is_empty(), &self.certificate) {
            let b = &c.boundary;
            let what = if c.cells.is_some() {
                "a valid subdivision of the region its boundary encloses into its cells: every cell positive and star-shaped, every two meeting face to face or not at all (bent quadrilaterals only between two cells that both have them)"
            } else {
                "a valid tetrahedralization of the region its boundary encloses: every tetrahedron positive, every two meeting face to face or not at all"
            };
            out += &format!(
                "ok: {what}, the boundary manifold, not meeting itself and wound once around ({} {}, {} {})\n",
                b.components,
                plural(b.components, "component", "components"),
                b.cavities,
                plural(b.cavities, "cavity", "cavities"),
            );
        } else if failures.is_empty() && !self.unchecked.is_empty() {
            let names: Vec<&str> = self.unchecked.iter().map(|u| u.halo.as_str()).collect();
            out += &format!(
                "ok as far as checked: no inverted or flat tetrahedron, no face in more than two or folded, the volume filled; NOT checked: the coverage of the surface by {}\n",
                names.join(", "),
            );
        } else if failures.is_empty() {
            let n = self.halos.len();
            let conform = if n == 1 {
                "1 halo conforms".to_string()
            } else {
                format!("{n} halos conform")
            };
            match &self.verification {
                None => out += &format!("ok: {conform}, no inverted or flat tetrahedron\n"),
                Some((_, v)) => {
                    out += &format!(
                        "ok: {conform}, no inverted or flat tetrahedron; {} curve samples correct, {} ambiguous, {} third sheet, none wrong; no spurious hidden sample\n",
                        v.correct, v.ambiguous, v.third_sheet
                    )
                }
            }
        }
        out
    }
}

impl Checked {
    /// What `halo4d check --json` prints: the file, the verdict (`passes`, `failures`), each
    /// mesh's name, statistics and (for a mesh without halo4d's layout) certificate, and for
    /// a folder the curves and the verification.
    pub fn json(&self) -> serde_json::Value {
        let failures = self.failures();
        serde_json::json!({
            "file": self.file,
            "scene": self.scene,
            "passes": failures.is_empty(),
            "failures": failures,
            "plain": self.plain,
            "meshes": self.halos.iter().map(|(name, stats)| serde_json::json!({
                "name": name,
                "format": self.mesh.as_ref().map(|m| &m.format),
                "stats": stats,
                "certificate": self.certificate,
                "pieces": self.pieces().iter().map(|p| serde_json::json!({
                    "file": p.file,
                    "tets": p.tets,
                    "faulty_tets": p.faulty,
                    "faults": p.faults.iter().map(|&(name, n)| (name.to_string(), n.into())).collect::<serde_json::Map<_, _>>(),
                })).collect::<Vec<_>>(),
            })).collect::<Vec<_>>(),
            "verification": self.verification.as_ref().map(|(curves, v)| serde_json::json!({
                "curves": curves,
                "halos": v,
            })),
            "unchecked": self.unchecked.iter().map(|u| serde_json::json!({
                "halo": u.halo,
                "why": u.why,
            })).collect::<Vec<_>>(),
        })
    }

    /// Writes the checked mesh (one without halo4d's layout) to `path` as a `.vtu` with
    /// each cell's faults as the cell field `fault` (the bits of [`Fault`]), and its
    /// `min_dihedral_deg`, `max_dihedral_deg` and `radius_ratio` (a mixed mesh's other cells:
    /// the extremes over the tetrahedra they were certified as): to open in ParaView and
    /// threshold on `fault`. The cells as the file gave them.
    pub fn write_marks(&self, path: &Path) -> Result<(), String> {
        let (Some(mesh), Some(c)) = (&self.mesh, &self.certificate) else {
            return Err(
                "--mark is for tetrahedral meshes without halo4d's layout; a halo's faults are counted by kind only".into(),
            );
        };
        let tets: Vec<[u32; 4]> = mesh.tets.iter().map(|&t| file_order(t)).collect();
        let others: Vec<(u8, &[u32])> = mesh
            .solids
            .iter()
            .map(|s| (s.kind.vtk_type(), s.used()))
            .collect();
        // Each cell's shape: a tetrahedron's own; another cell's extremes over its
        // tetrahedra.
        let mut shapes = c.shapes[..tets.len()].to_vec();
        if let Some(cells) = &c.cells {
            shapes.extend(cells.first_tet.windows(2).map(|w| {
                c.shapes[w[0]..w[1]]
                    .iter()
                    .fold([f32::INFINITY, f32::NEG_INFINITY, f32::INFINITY], |a, s| {
                        [a[0].min(s[0]), a[1].max(s[1]), a[2].min(s[2])]
                    })
            }));
        }
        let column = |k: usize| shapes.iter().map(|s| s[k]).collect::<Vec<f32>>();
        let (lo, hi, ratio) = (column(0), column(1), column(2));
        write_tetrahedra_vtu(
            path,
            &mesh.positions,
            &tets,
            &others,
            &[
                ("fault", CellValues::U32(c.cell_faults())),
                ("min_dihedral_deg", CellValues::F32(&lo)),
                ("max_dihedral_deg", CellValues::F32(&hi)),
                ("radius_ratio", CellValues::F32(&ratio)),
            ],
        )
        .map_err(|e| format!("cannot write {}: {e}", path.display()))
    }

    /// For a mesh read from pieces (a `.pvtu`), each piece's tetrahedra and how many have
    /// each fault ([`Fault`], a cavity not counted), so that a fault is named with the
    /// piece it is in (an overlap or gap between two pieces: in both); empty otherwise.
    pub fn pieces(&self) -> Vec<Piece> {
        let (Some(mesh), Some(c)) = (&self.mesh, &self.certificate) else {
            return Vec::new();
        };
        let mut out: Vec<Piece> = mesh
            .pieces
            .iter()
            .map(|file| Piece {
                file: file.clone(),
                tets: 0,
                faulty: 0,
                faults: Vec::new(),
            })
            .collect();
        let mut counts = vec![[0usize; Fault::ALL.len()]; out.len()];
        for (&k, &bits) in mesh.piece_of.iter().zip(c.cell_faults()) {
            let Some(piece) = out.get_mut(k as usize) else {
                continue;
            };
            piece.tets += 1;
            let bits = bits & !Fault::CAVITY;
            if bits != 0 {
                piece.faulty += 1;
                for (i, f) in Fault::ALL.iter().enumerate() {
                    counts[k as usize][i] += usize::from(bits & f.bit != 0);
                }
            }
        }
        for (piece, counts) in out.iter_mut().zip(&counts) {
            piece.faults = Fault::ALL
                .iter()
                .zip(counts)
                .filter(|(_, n)| **n > 0)
                .map(|(f, &n)| (f.name, n))
                .collect();
        }
        out
    }

    /// How many cells have each fault bit, for the line `--mark` prints.
    pub fn marked(&self) -> Vec<(&'static str, usize)> {
        let Some(c) = &self.certificate else {
            return Vec::new();
        };
        Fault::ALL
            .iter()
            .map(|f| {
                (
                    f.name,
                    c.cell_faults().iter().filter(|&&b| b & f.bit != 0).count(),
                )
            })
            .filter(|&(_, n)| n > 0)
            .collect()
    }
}

fn plural<'a>(n: usize, one: &'a str, many: &'a str) -> &'a str {
    if n == 1 { one } else { many }
}

/// A certificate's convention, boundary and quality as text.
fn certificate_text(c: &Certificate) -> String {
    let b = &c.boundary;
    let q = &c.quality;
    let mut out = String::new();
    match c.convention {
        crate::certify::Convention::Positive => {}
        crate::certify::Convention::Reversed => {
            out += "convention: every tetrahedron is negative in the file's convention; read in the other (its vertices' order reversed)\n"
        }
    }
    let windings: Vec<String> = b
        .windings
        .iter()
        .map(|w| w.map_or("?".into(), |w| w.to_string()))
        .collect();
    let rows = [
        ("boundary faces", b.faces.to_string()),
        ("components", b.components.to_string()),
        ("cavities", b.cavities.to_string()),
    ]
    .into_iter()
    .chain(
        b.fault_counts()
            .into_iter()
            .map(|(name, count, _)| (name, count.to_string())),
    )
    .chain([(
        "windings just inside",
        if windings.len() > 12 {
            format!("{} ...", windings[..12].join(" "))
        } else {
            windings.join(" ")
        },
    )]);
    if let Some(cells) = &c.cells {
        out += &cells_text(cells);
    }
    out += "\nboundary\n";
    for (k, v) in rows {
        let _ = writeln!(out, "  {k:<22}{v}");
    }
    let _ = writeln!(
        out,
        "\nquality (reported, not judged)\n  dihedral angles       {:.3} to {:.3} degrees\n  radius ratio          {:.4} smallest, {:.4} mean (1 for the regular tetrahedron)",
        q.min_dihedral_deg, q.max_dihedral_deg, q.min_radius_ratio, q.mean_radius_ratio
    );
    let most = q
        .radius_ratio_histogram
        .iter()
        .map(|b| b.count)
        .max()
        .unwrap_or(0)
        .max(1);
    out += "  radius ratio histogram\n";
    for bin in &q.radius_ratio_histogram {
        let bar = "#".repeat((40 * bin.count).div_ceil(most));
        let line = format!(
            "    {:.1} to {:.1}  {:>10}  {bar}",
            bin.from, bin.to, bin.count
        );
        let _ = writeln!(out, "{}", line.trim_end());
    }
    out += "  worst (smallest radius ratio)\n";
    for w in q.worst.iter().take(5) {
        let of = match c.cells.as_ref().map(|cells| cells.cell_of(w.tet)) {
            Some((kind, id)) if kind != "tetrahedron" => format!(" (of {kind} {id})"),
            _ => String::new(),
        };
        let _ = writeln!(
            out,
            "    tetrahedron {:>10}{of}: radius ratio {:.3e}, dihedral angles {:.4} to {:.4} degrees",
            w.tet, w.radius_ratio, w.min_dihedral_deg, w.max_dihedral_deg
        );
    }
    out
}

/// A mixed mesh's cells, its quadrilaterals and its first faulty cells, as text.
fn cells_text(c: &crate::certify::Cells) -> String {
    let mut out = String::from("\ncells\n");
    let rows = [
        ("tetrahedra", c.tetrahedra.to_string()),
        ("hexahedra", c.hexahedra.to_string()),
        ("wedges", c.wedges.to_string()),
        ("pyramids", c.pyramids.to_string()),
        (
            "certified as",
            format!(
                "{} tetrahedra (a hexahedron 12 and a wedge 8 around their corners' mean, a pyramid 2)",
                c.certified_tetrahedra
            ),
        ),
        ("quadrilaterals", c.quads.to_string()),
        (
            "nonplanar_quads",
            if c.nonplanar_quads > 0 {
                let w = c.max_warp_deg;
                let w = if w < 1e-3 {
                    format!("{w:.2e}")
                } else {
                    format!("{w:.4}")
                };
                format!("{} (the largest warp {w} degrees)", c.nonplanar_quads)
            } else {
                "0".into()
            },
        ),
        ("nonconforming_quads", c.nonconforming_quads.to_string()),
        ("undecided_quads", c.undecided_quads.to_string()),
        ("cells with a fault", c.faulty_cells.to_string()),
    ];
    for (k, v) in rows {
        let _ = writeln!(out, "  {k:<22}{v}");
    }
    for f in &c.faulty {
        let _ = writeln!(out, "    {} {}: {}", f.kind, f.id, f.faults.join(", "));
    }
    if c.faulty_cells > c.faulty.len() {
        let _ = writeln!(out, "    ... and {} more", c.faulty_cells - c.faulty.len());
    }
    out
}

/// The one `.glb` in `dir`, or why there is none.
fn scene_glb(dir: &Path) -> Result<PathBuf, String> {
    let entries = std::fs::read_dir(dir).map_err(|e| format!("cannot read the folder: {e}"))?;
    let mut glbs = Vec::new();
    for entry in entries {
        let path = entry
            .map_err(|e| format!("cannot read the folder: {e}"))?
            .path();
        if path.is_file()
            && path
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("glb"))
        {
            glbs.push(path);
        }
    }
    glbs.sort();
    match glbs.len() {
        1 => Ok(glbs.remove(0)),
        0 => Err(
            "no .glb in the folder: give a folder that `halo4d build` wrote with outputs.glb on"
                .into(),
        ),
        n => Err(format!(
            "{n} .glb files in the folder ({}); expected one, the scene's <name>.glb: check a file instead",
            glbs.iter()
                .filter_map(|p| p.file_name())
                .map(|n| n.to_string_lossy())
                .collect::<Vec<_>>()
                .join(", ")
        )),
    }
}

/// The checker's statistics as a table: a row per statistic, in the struct's order, and a
/// column per halo; for tetrahedra without a halo layout (`plain`), headed `mesh`, without
/// the rows only a halo has.
fn stats_table(halos: &[(String, CheckStats)], plain: bool) -> String {
    let columns: Vec<Vec<(String, String)>> = halos
        .iter()
        .map(|(_, s)| {
            let mut rows = stat_rows(s);
            rows.retain(|(k, _)| !(plain && HALO_ONLY.contains(&k.as_str())));
            rows
        })
        .collect();
    let labels: Vec<&str> = columns
        .first()
        .map(|c| c.iter().map(|(k, _)| k.as_str()).collect())
        .unwrap_or_default();
    let label_width = labels.iter().map(|l| l.len()).max().unwrap_or(0).max(4);
    let widths: Vec<usize> = halos
        .iter()
        .zip(&columns)
        .map(|((n, _), c)| {
            c.iter()
                .map(|(_, v)| v.len())
                .max()
                .unwrap_or(0)
                .max(n.len())
        })
        .collect();
    let mut out = format!("{:<label_width$}", if plain { "mesh" } else { "halo" });
    for ((n, _), w) in halos.iter().zip(&widths) {
        let _ = write!(out, "  {n:>w$}");
    }
    out.push('\n');
    for (row, label) in labels.iter().enumerate() {
        let _ = write!(out, "{label:<label_width$}");
        for (c, w) in columns.iter().zip(&widths) {
            let _ = write!(out, "  {:>w$}", c[row].1);
        }
        out.push('\n');
    }
    out
}

/// The fields of `stats` in declaration order, formatted. Read through serde, so that a
/// statistic added to the checker shows up here too; serde_json's own map sorts its keys,
/// so the fields are collected by a visitor that keeps their order.
fn stat_rows(stats: &CheckStats) -> Vec<(String, String)> {
    struct Rows(Vec<(String, serde_json::Value)>);
    impl<'de> serde::Deserialize<'de> for Rows {
        fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
            struct Visit;
            impl<'de> serde::de::Visitor<'de> for Visit {
                type Value = Rows;
                fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                    f.write_str("a map")
                }
                fn visit_map<A: serde::de::MapAccess<'de>>(
                    self,
                    mut map: A,
                ) -> Result<Rows, A::Error> {
                    let mut rows = Vec::new();
                    while let Some(entry) = map.next_entry()? {
                        rows.push(entry);
                    }
                    Ok(Rows(rows))
                }
            }
            d.deserialize_map(Visit)
        }
    }
    let rows = serde_json::to_string(stats)
        .and_then(|text| serde_json::from_str::<Rows>(&text))
        .map(|r| r.0)
        .unwrap_or_default();
    rows.into_iter()
        // The logarithm is the volume's own row where the volume overflows.
        .filter(|(k, _)| k != "volume_log10")
        .map(|(k, v)| {
            if k == "volume" && !stats.volume.is_finite() && stats.volume_log10.is_finite() {
                // Beyond an f64: the decimal from the logarithm.
                let (e, m) = (stats.volume_log10.floor(), stats.volume_log10.fract());
                return (k, format!("{:.3}e{e} (beyond an f64)", 10f64.powf(m)));
            }
            let text = match v {
                serde_json::Value::Number(n) if n.is_u64() || n.is_i64() => n.to_string(),
                serde_json::Value::Number(n) => {
                    let x = n.as_f64().unwrap_or(f64::NAN);
                    if x == 0.0 || (1e-2..1e6).contains(&x.abs()) {
                        format!("{x:.4}")
                    } else {
                        format!("{x:.3e}")
                    }
                }
                // serde_json writes a non-finite number as null.
                serde_json::Value::Null => "not finite".into(),
                other => other.to_string(),
            };
            (k, text)
        })
        .collect()
}
