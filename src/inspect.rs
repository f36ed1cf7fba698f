//! `halo4d check`: what a build wrote, checked again from the files alone.
//!
//! Takes: a `.glb` or legacy `.vtk` file ([`check_file`]; a `.vtk` without halo4d's layout
//! gets the checks that need none, [`check_tetrahedra`]), or a build's output folder with
//! its one scene `.glb` ([`check_dir`]). Gives: [`Checked`], each halo's [`CheckStats`] and,
//! for a folder, the intersection curves recomputed from the file's surfaces and the halos'
//! [`Verification`] against them.
//! Guarantees: the verdict ([`Checked::failures`]) is a build's ([`crate::Built::failures`]),
//! from the same library functions: [`CheckStats::verdict`], [`CurvesReport::failures`],
//! [`Verification::failures`].

use crate::check::{CheckStats, HALO_ONLY, check, check_tetrahedra};
use crate::import::{self, FileTetrahedra, ImportError, ImportedHalo, ImportedScene};
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
    /// its tetrahedra's, from [`check_tetrahedra`]).
    pub halos: Vec<(String, CheckStats)>,
    /// For a `.vtk` without halo4d's layout: why it is not read as a halo. Its tetrahedra
    /// get the checks that need no layout; the halo's own (offset faces, quads, surface
    /// faces) cannot be made.
    pub plain: Option<String>,
    /// For a folder: the curves recomputed from the file's surfaces, and the halos
    /// verified against them.
    pub verification: Option<(CurvesReport, Verification)>,
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
    let (halos, plain) = match read {
        FileTetrahedra::Halos(halos) => (check_halos(halos.iter()), None),
        FileTetrahedra::Plain(mesh) => (
            vec![(
                mesh.name.clone(),
                check_tetrahedra(&mesh.positions, &mesh.tets),
            )],
            Some(mesh.why),
        ),
    };
    Ok(Checked {
        file: file.to_path_buf(),
        scene: None,
        halos,
        plain,
        verification: None,
    })
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
    let halos = check_halos(scene.surfaces.iter().filter_map(|s| s.halo.as_ref()));
    let (curves, verification) = verify_scene(&scene);
    Ok(Checked {
        file,
        scene: scene.name.clone(),
        halos,
        plain: None,
        verification: Some((curves.report, verification)),
    })
}

/// Recomputes the intersection curves of a scene read from its `.glb` and verifies its
/// halos against them, as a build does ([`crate::pipeline::Sampled::build`]).
pub fn verify_scene(scene: &ImportedScene) -> (Curves, Verification) {
    let curves = intersect::curves(&scene.parts(&Curves::default()).sheets());
    let verification = verify::verify(&scene.parts(&curves));
    (curves, verification)
}

fn check_halos<'a>(halos: impl Iterator<Item = &'a ImportedHalo>) -> Vec<(String, CheckStats)> {
    halos.map(|h| (h.name.clone(), check(&h.mesh))).collect()
}

impl Checked {
    /// The verdict: what keeps the file from passing, empty when it passes. Every halo
    /// passes the checker; for a folder also every curve is resolved and the verification
    /// finds no wrong curve sample and no spuriously hidden surface sample.
    pub fn failures(&self) -> Vec<String> {
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
                "not a halo: {why}. Checked as tetrahedra: orientation, repeated tetrahedra, faces in more than two, the volume against the boundary's; not checked: the halo's offset faces, quads and surface faces\n"
            );
        }
        if self.halos.is_empty() {
            out += "no halo in the file\n";
        } else {
            out += &stats_table(&self.halos, self.plain.is_some());
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
        if failures.is_empty() && self.plain.is_some() {
            out += "ok: no inverted, flat or repeated tetrahedron, no face in more than two, and the tetrahedra fill the volume their boundary encloses\n";
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
        .map(|(k, v)| {
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
