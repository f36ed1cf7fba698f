//! What a build reports (`report.json`): counts, bounds, mesh statistics, timings, memory,
//! the picture and the verdict.

use super::Stages;
use super::built::SurfaceProduct;
use crate::halo::HaloReport;
use crate::intersect::CurvesReport;
use crate::render;
use crate::sample::{self, Audit, MeshStats, Proof, Sampling, Source};
use crate::scene::Scene;
use crate::stipple::Stipples;
use crate::surfaces::Topology;
use crate::verify::Verification;
use serde::Serialize;

/// `report.json`'s `memory`: the peak the build was estimated to need
/// (`crate::memory::build_bytes`) against the limit (`HALO4D_MAX_MEMORY` gigabytes, or
/// three quarters of the machine's memory), and the peak it reached, in GB. The picture is
/// estimated on its own when it is made.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct MemoryReport {
    /// Estimated peak resident memory of the build.
    pub estimate_gb: f64,
    /// The limit a build refuses to go beyond.
    pub limit_gb: f64,
    /// The process's peak resident memory when `report.json` was written, the build's
    /// memory freed (null where the system does not say).
    pub peak_gb: Option<f64>,
}

/// `report.json`'s `crowding`: per surface, on average over points spread over it by area,
/// how many triangles' boxes hold the point (`triangles`, empty when the build makes
/// neither curves nor halos) and how many halo tetrahedra's boxes, of all the halos
/// (`halos`, empty without halos): what a query of the curves, the verification and the
/// picture costs there. A build is refused beyond
/// [`SURFACE_CROWDING`](crate::limits::SURFACE_CROWDING) and
/// [`HALO_CROWDING`](crate::limits::HALO_CROWDING).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct CrowdingReport {
    /// Triangles, per surface.
    pub triangles: Vec<f64>,
    /// Halo tetrahedra, per surface.
    pub halos: Vec<f64>,
}

/// How a surface was sampled, and the audit of the mesh (`report.json`'s `sampling`).
#[derive(Clone, Debug, Serialize)]
pub struct SamplingReport {
    /// `adaptive`, `uniform`, or `file` for a mesh read from a file (not sampled, not
    /// audited: the mesh is the surface, its errors are 0).
    pub method: &'static str,
    /// The absolute tolerance the adaptive sampler aimed at.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<f64>,
    /// The same, relative to `diagonal`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub relative_tolerance: Option<f64>,
    /// The adaptive sampler's triangle budget.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_triangles: Option<usize>,
    /// Diagonal of the surface's 4D bounding box, the length relative values refer to.
    pub diagonal: f64,
    /// Triangles.
    pub triangles: usize,
    /// Vertices.
    pub vertices: usize,
    /// Audited largest distance, triangle to surface, in R^4.
    pub max_error: f64,
    /// Audited root mean square distance.
    pub rms_error: f64,
    /// `max_error / diagonal`.
    pub max_error_relative: f64,
    /// `rms_error / diagonal`.
    pub rms_error_relative: f64,
    /// Proven largest distance, triangle to surface, in R^4, at every point of every
    /// triangle (interval arithmetic: [`sample::triangle_bound`]); absent for a mesh file,
    /// and `null` when some triangle has no finite bound (`unproven_triangles`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub proven_max_error: Option<Option<f64>>,
    /// `proven_max_error / diagonal`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub proven_max_error_relative: Option<Option<f64>>,
    /// Triangles without a finite proven bound (a formula undefined on part of one).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unproven_triangles: Option<usize>,
    /// The bound the adaptive sampler held the triangles to: `audited` or `proven`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bound: Option<sample::ErrorBound>,
    /// Whether the sampler met its tolerance everywhere (false when its triangle budget
    /// stopped it).
    pub complete: bool,
    /// When the budget stopped adaptive sampling: the audited max error of a uniform grid
    /// of about as many triangles ([`sample::uniform_error`]), to compare `max_error` with.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub uniform_max_error: Option<f64>,
    /// Milliseconds spent sampling.
    pub ms: f64,
    /// Milliseconds spent auditing (with the uniform grid of `uniform_max_error`).
    pub audit_ms: f64,
    /// Milliseconds spent proving `proven_max_error`.
    pub proven_ms: f64,
}

impl SamplingReport {
    pub(super) fn new(
        method: &'static str,
        sampling: &Sampling,
        sampled: &sample::Sampled,
        audit: &Audit,
        proof: Option<&Proof>,
        uniform_max_error: Option<f64>,
        [ms, audit_ms, proven_ms]: [f64; 3],
    ) -> Self {
        let (max_rel, rms_rel) = audit.relative(sampled.diagonal);
        SamplingReport {
            method,
            max_triangles: match *sampling {
                Sampling::Adaptive { max_triangles, .. } if method == "adaptive" => {
                    Some(max_triangles)
                }
                _ => None,
            },
            tolerance: sampled.tolerance,
            relative_tolerance: sampled.tolerance.map(|t| t / sampled.diagonal),
            diagonal: sampled.diagonal,
            triangles: sampled.mesh.triangles.len(),
            vertices: sampled.mesh.vertex_count(),
            max_error: audit.max_error,
            rms_error: audit.rms_error,
            max_error_relative: max_rel,
            rms_error_relative: rms_rel,
            proven_max_error: proof.map(|p| p.max_error),
            proven_max_error_relative: proof.map(|p| p.max_error.map(|m| m / sampled.diagonal)),
            unproven_triangles: proof.map(|p| p.unproven),
            bound: match *sampling {
                Sampling::Adaptive { bound, .. } if method == "adaptive" => Some(bound),
                _ => None,
            },
            complete: sampled.complete,
            uniform_max_error,
            ms,
            audit_ms,
            proven_ms,
        }
    }

    /// The warning a build prints when the sampler stopped short of its tolerance.
    pub fn warning(&self, surface: &str) -> Option<String> {
        if self.complete {
            return None;
        }
        Some(format!(
            "surface `{surface}`: the triangle budget (max_triangles = {}) stopped refinement at {} triangles before every triangle met the tolerance {:.3e}; the audited max error is {:.3e} ({:.3e} of the diagonal; a uniform grid of as many triangles: {:.3e}). Raise max_triangles or the tolerance.",
            self.max_triangles.unwrap_or(0),
            self.triangles,
            self.tolerance.unwrap_or(f64::NAN),
            self.max_error,
            self.max_error_relative,
            self.uniform_max_error.unwrap_or(f64::NAN),
        ))
    }
}

/// The warnings a build prints for a surface as it is: a mesh file that is not a manifold
/// (the sampler's meshes always are: what the halos and curves meet there is what the file
/// gives), a formula whose open sides meet ([`crate::surfaces::Formula::meeting_sides`]:
/// it builds as an open surface).
pub(super) fn surface_warnings(surface: &str, source: &Source, stats: &MeshStats) -> Vec<String> {
    match source {
        Source::Mesh(_) if !stats.is_manifold() => vec![format!(
            "surface `{surface}`: the mesh file is not a manifold: {} edges in more than two triangles, {} triangles of zero area; halos and curves follow the triangles as they are, and verification may call samples there ambiguous",
            stats.non_manifold_edges, stats.degenerate_triangles
        )],
        Source::Parametric(crate::surfaces::Surface::Formula(f)) => f
            .meeting_sides()
            .into_iter()
            .map(|w| format!("surface `{surface}`: {w}"))
            .collect(),
        _ => Vec::new(),
    }
}

/// Milliseconds spent in each stage. Every piece of work a build does is in one of them, so
/// that they add up to `total`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, serde::Deserialize)]
#[serde(default)]
pub struct Timings {
    /// Before the first stage: reading the scene and, when its view is `auto`, the view
    /// search, from the moment `halo4d` started (0 where a program calls the library).
    pub setup: f64,
    /// Sampling, all surfaces.
    pub sample: f64,
    /// Auditing the samples and validating their meshes, all surfaces.
    pub audit: f64,
    /// Proving the bound of every triangle's distance from its surface (interval
    /// arithmetic), all surfaces.
    pub prove: f64,
    /// View (rotation, projection, normals), all surfaces.
    pub view: f64,
    /// The checks before the slow stages: the scene's scale and the memory it needs, and
    /// how the triangles' and the halos' boxes pile up (`crowding`).
    pub guards: f64,
    /// Halos: thickening, tetrahedra, checking, all surfaces.
    pub halo: f64,
    /// Intersection curves, all surfaces together.
    pub curves: f64,
    /// Moving the curves onto the analytic surfaces.
    pub refine: f64,
    /// Certifying the double curves of the true surfaces (`curves.certify`).
    pub certify: f64,
    /// Verifying the halos against the curves.
    pub verify: f64,
    /// Ranking the stipples, all surfaces.
    pub stipples: f64,
    /// Rendering the picture.
    pub render: f64,
    /// Writing the outputs and moving them into place (replacing a former build's files
    /// is part of it).
    pub export: f64,
    /// Freeing the build's memory once its files are written.
    pub free: f64,
    /// The build's wall time, measured: from the start of `setup` to `report.json`
    /// written, which is the process's wall time but for its start and exit. The stages
    /// add up to it but for what lies between them (well under 1%). For the report of a
    /// build made earlier ([`crate::write`]), the sum of the stages.
    pub total: f64,
}

impl Timings {
    /// Each stage's name and milliseconds, in the order a build runs them.
    pub fn stages(&self) -> [(&'static str, f64); 15] {
        [
            ("setup", self.setup),
            ("sample", self.sample),
            ("audit", self.audit),
            ("prove", self.prove),
            ("view", self.view),
            ("guards", self.guards),
            ("halo", self.halo),
            ("stipples", self.stipples),
            ("curves", self.curves),
            ("refine", self.refine),
            ("certify", self.certify),
            ("verify", self.verify),
            ("render", self.render),
            ("export", self.export),
            ("free", self.free),
        ]
    }

    /// The sum of the stages.
    pub fn sum(&self) -> f64 {
        self.stages().iter().map(|(_, t)| t).sum()
    }
}

/// Bounding box.
#[derive(Clone, Debug, Serialize)]
pub struct Bounds {
    /// Lower corner.
    pub min: Vec<f64>,
    /// Upper corner.
    pub max: Vec<f64>,
}

/// What the report says of one surface.
#[derive(Clone, Debug, Serialize)]
pub struct SurfaceReport {
    /// Mesh name.
    pub name: String,
    /// Catalogue type.
    #[serde(rename = "type")]
    pub type_name: String,
    /// Parameter patches.
    pub patches: usize,
    /// Sampling and its audit.
    pub sampling: SamplingReport,
    /// Vertices.
    pub vertices: usize,
    /// Triangles.
    pub triangles: usize,
    /// Expected topology.
    pub topology: Topology,
    /// Measured combinatorics.
    pub mesh: MeshStats,
    /// Bounding box in R^4 before the view.
    pub bounds_4d: Option<Bounds>,
    /// Bounding box of the projection.
    pub bounds_3d: Option<Bounds>,
    /// Range of w-depth after the view.
    pub w_range: Option<[f64; 2]>,
    /// The halo (null when no output needs one).
    pub halo: Option<HaloReport>,
    /// Stipples ranked on the 4D mesh (absent when none were made).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stipples: Option<usize>,
}

/// `report.json`'s `picture`: how to reproduce the picture's projection, the halos' width in
/// it, and the share of the curves it shows (`render::visible`).
#[derive(Clone, Debug, Serialize)]
pub struct PictureReport {
    /// The camera, in the projected scene's coordinates.
    #[serde(flatten)]
    pub camera: render::visible::PictureCamera,
    /// The cutaway (`render.clip`), when set: the points where `normal · p > offset` holds
    /// for every plane are removed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub clip: Option<render::clip::Clip>,
    /// The halos' half-width asked for, in scene units.
    pub rho: f64,
    /// The same in pixels at the depth the camera looks at.
    pub gap_px: f64,
    /// The curves' projected length and the share of it in view.
    #[serde(flatten)]
    pub curves: render::visible::CurveVisibility,
}

/// `report.json`.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// Version of halo4d that wrote it.
    pub halo4d: &'static str,
    /// Scene name.
    pub scene_name: String,
    /// Per surface.
    pub surfaces: Vec<SurfaceReport>,
    /// Which stages after the projection ran (those the outputs need).
    pub stages: Stages,
    /// The intersection curves of all surfaces together (null when not computed).
    pub curves: Option<CurvesReport>,
    /// The halos checked against the curves (null when not verified).
    pub halo_verification: Option<Verification>,
    /// Milliseconds per stage.
    pub timings_ms: Timings,
    /// Memory estimated before the halos, against the limit.
    pub memory: MemoryReport,
    /// The boxes piled up at the surfaces' points.
    pub crowding: CrowdingReport,
    /// Warnings, also printed on stderr.
    pub warnings: Vec<String>,
    /// The picture: its camera, halo width and how much of the curves it shows (absent when
    /// no picture was drawn).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub picture: Option<PictureReport>,
    /// Whether the build is verified: [`crate::Built::failures`] found nothing in the stages that
    /// ran.
    pub verified: bool,
    /// What [`crate::Built::failures`] found.
    pub failures: Vec<String>,
    /// Files written, relative to the output folder.
    pub files: Vec<String>,
    /// The scene as parsed, with every default filled in.
    pub scene: Scene,
}

impl Report {
    /// What `halo4d build` prints on stderr: per surface its mesh, the curves, the halo
    /// verification, the timings and the memory, one line each.
    pub fn summary(&self) -> String {
        let mut out = String::new();
        for s in &self.surfaces {
            out += &format!(
                "{:<24} {:>9} vertices {:>9} triangles  Euler characteristic {}\n",
                s.name, s.vertices, s.triangles, s.mesh.euler_characteristic
            );
        }
        match &self.curves {
            Some(c) => out += &format!("{}\n", c.summary()),
            None => out += "curves: not computed (no output uses them)\n",
        }
        match &self.halo_verification {
            Some(v) => {
                out += &format!(
                    "halo verification: {} curve samples: {} correct, {} wrong, {} ambiguous, {} third sheet; {} surface samples, {} far tetrahedra, {} spurious\n",
                    v.curve_samples,
                    v.correct,
                    v.wrong,
                    v.ambiguous,
                    v.third_sheet,
                    v.surface_samples,
                    v.far_tetrahedra,
                    v.spurious_hidden_samples
                )
            }
            None => {
                out += "halo verification: not run (no halo file written; `outputs.verify: true` asks for it)\n"
            }
        }
        let stages: Vec<String> = (self.timings_ms.stages().iter())
            .map(|(name, t)| format!("{name} {t:.1} ms"))
            .collect();
        out += &format!(
            "{}, total {:.1} ms\n",
            stages.join(", "),
            self.timings_ms.total
        );
        out += &format!(
            "memory: about {:.2} GB estimated, limit {:.2} GB{}\n",
            self.memory.estimate_gb,
            self.memory.limit_gb,
            self.memory
                .peak_gb
                .map(|gb| format!(", peak {gb:.2} GB"))
                .unwrap_or_default()
        );
        out
    }
}

pub(super) fn surface_report(p: &SurfaceProduct, halo: bool) -> SurfaceReport {
    SurfaceReport {
        name: p.name.clone(),
        type_name: p.surface.type_name().to_string(),
        patches: p.surface.patch_count(),
        sampling: p.sampling.clone(),
        vertices: p.mesh.vertex_count(),
        triangles: p.mesh.triangles.len(),
        // A mesh file's from the statistics already measured, not by validating it again.
        topology: match &p.surface {
            Source::Parametric(s) => s.topology(),
            Source::Mesh(_) => sample::mesh_topology(&p.stats),
        },
        mesh: p.stats,
        bounds_4d: p.mesh.bounds().map(|(lo, hi)| Bounds {
            min: lo.to_array().to_vec(),
            max: hi.to_array().to_vec(),
        }),
        bounds_3d: p.projected.bounds().map(|(lo, hi)| Bounds {
            min: lo.to_array().to_vec(),
            max: hi.to_array().to_vec(),
        }),
        w_range: p.projected.w_range(),
        halo: halo.then(|| p.halo_report.clone()),
        stipples: p.stipples.as_ref().map(Stipples::len),
    }
}
