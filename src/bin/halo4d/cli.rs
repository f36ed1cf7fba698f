//! The `halo4d` command line's commands and flags (clap), apart from what they do, so that
//! the tests can parse every command the README shows against them.

use clap::{Args, Parser, Subcommand};
use halo4d::limits;
use halo4d::{animate::FrameRange, animate::Shard, render::RenderMode, render::Style};
use std::path::PathBuf;

/// Surfaces in 4D turned into verified 3D geometry: glTF for Blender, PLY for MeshLab.
#[derive(Parser)]
#[command(name = "halo4d", version, about, long_about = None)]
pub struct Cli {
    /// The command.
    #[command(subcommand)]
    pub command: Command,
}

/// The commands.
#[derive(Subcommand)]
pub enum Command {
    /// Build a scene: sample, view and export its surfaces.
    Build(BuildArgs),
    /// Speed against error: for each surface of a scene, the adaptive sampler and the
    /// coarsest uniform grid at relative tolerances 1e-2 to 1e-5, audited alike, each mesh
    /// with its self-intersection curves in the scene's view (time, the mesh curve's error,
    /// the refined curve's residual). Writes speed_vs_error.csv, speed_vs_error.png and
    /// curves_vs_error.png.
    Sweep(SweepArgs),
    /// Render a scene's picture (its `camera` and `render` settings, with the flags below
    /// overriding them) to a PNG.
    Render(RenderArgs),
    /// Animate a scene: the frames of its `animation`, each the build of the scene in that
    /// frame's 4D view and camera, its halos verified against its curves, its picture
    /// (frame-00042.png) and record (frame-00042.json: view, counts, verification,
    /// timings). The surfaces are sampled once. A rerun makes only the frames without a
    /// record; any number of processes may fill one folder side by side (`--shard`).
    ///
    /// Exit status 0 when every frame of the run is verified, 3 when one is not (its
    /// record says why), 1 on an error. With --status: 0 when every frame of the folder is
    /// done and verified, 1 when not, 2 when the folder is not an animation's. With
    /// --assemble: 0 when the animation was written, 1 when frames are missing or not
    /// verified (listed) or the folder is unreadable.
    Animate(AnimateArgs),
    /// List the surface catalogue with each surface's parameters and defaults.
    List,
    /// Build every scene of a folder (paper 000's figures by default) into a gallery: each
    /// figure's picture and report in a folder of its own, an index page (index.html) with
    /// each picture's description, the share of its double curves in view and its
    /// verdict, and a contact sheet of all the pictures (gallery.png).
    ///
    /// Exit status 0 when every figure is verified, 3 when one is not, 1 on an error.
    Gallery(GalleryArgs),
    /// Search the 4D view and camera orbit that show the most of a scene's double curves
    /// (their visible length in the picture times the share visible, by rays from the
    /// eye), on a coarse grid of the surfaces; prints what it found and writes the scene
    /// with that view (`view.rotation`, `camera.azimuth` and `camera.elevation`; the rest
    /// of the file as it was) to --out.
    View(ViewArgs),
    /// Check the halos of a .glb or .vtk file with the independent checker, or a build's
    /// output folder: its halos and their verification against the intersection curves.
    ///
    /// With a FILE, prints the checker's statistics, one column per halo. Another program's
    /// tetrahedral mesh (.vtk, .vtu, Gmsh .msh 2.2 or 4.1, Medit .mesh, TetGen .node/.ele)
    /// gets the checks that need no halo layout. Exit status 0 when
    /// every halo passes the checker (conforms, no inverted, flat or undecidable
    /// tetrahedron, a volume defect of at most 1e-9), 1 when one does not, 2 when the file
    /// cannot be read as halos.
    ///
    /// With a folder (what `halo4d build --out DIR` wrote), reads its one .glb, runs the
    /// checker on each halo, recomputes the intersection curves of the file's surfaces and
    /// verifies the halos against them (along every curve the far sheet hidden by the near
    /// sheet's halo and the near sheet visible; nowhere a halo cutting a gap away from its
    /// sheet), and prints both. Exit status 0 when every halo passes the checker, every
    /// curve is resolved and the verification finds no wrong curve sample and no spurious
    /// hidden sample (a build's own verdict), 1 when something failed (a `FAILED` line says
    /// what), 2 when the folder or its .glb cannot be read.
    Check(CheckArgs),
    /// A motion picture of each surface of a scene: the surface cut by the hyperplanes
    /// <n, x> = c of the surface's own 4D coordinates, its critical levels (births, saddles,
    /// deaths; on a boundary, births, deaths, joins and splits of arcs) found on the mesh and
    /// refined by Newton's method on the exact surface, one still between each pair of
    /// consecutive critical levels drawn as a link diagram (seen from the scene's camera,
    /// every under-strand broken), checked by Morse theory: #births - #saddles + #deaths = χ
    /// (+ #boundary births - #boundary joins on a surface with boundary), and across each
    /// critical level the slice's components change as its event says. Writes <name>-motion.png and .svg (the
    /// stills in one strip), <name>-motion.glb (their curves as tubes), <name>-still-NN.ply
    /// (each still's curves in the hyperplane's frame) and motion.json.
    ///
    /// Exit status 0 when every check passes, 3 when one fails (a FAILED line says which;
    /// a degenerate direction, such as one with critical circles, is one: tilt it with
    /// --perturb), 1 on an error.
    Slice(SliceArgs),
}

/// The arguments of `halo4d build`.
#[derive(Args)]
pub struct BuildArgs {
    /// Scene file (JSON). Without it, the built-in default scene (a spun trefoil in the
    /// 4D view the view search found) is built.
    pub scene: Option<PathBuf>,
    /// Output folder [default: exports/<scene name>/].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
    /// Stop the build after SECONDS (the view search's and the build's time, from the
    /// start): nothing of it is written, and the exit status is 124.
    #[arg(long, value_name = "SECONDS", value_parser = seconds)]
    pub timeout: Option<f64>,
    /// Exit 0 even when the build's own verification fails (the files are written, and
    /// marked `verified: false`, either way).
    #[arg(long)]
    pub allow_unverified: bool,
}

/// The arguments of `halo4d sweep`.
#[derive(Args)]
pub struct SweepArgs {
    /// Scene file (JSON) [default: the built-in default scene].
    pub scene: Option<PathBuf>,
    /// Output folder.
    #[arg(long, default_value = "exports/reports")]
    pub out: PathBuf,
    /// Relative tolerances, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = halo4d::sweep::TOLERANCES)]
    pub tolerances: Vec<f64>,
    /// The most triangles of any one mesh.
    #[arg(long, default_value_t = limits::SWEEP_TRIANGLES)]
    pub max_triangles: usize,
    /// Instead: the picture's speed against error. Builds the scene, renders it in the
    /// exact mode and with each of --slices, and writes render_speed_vs_error.csv and
    /// render_speed_vs_error.png (time, share of pixels whose hidden/visible verdict
    /// differs from the exact mode's, mean and 99th-percentile pixel difference).
    #[arg(long)]
    pub render: bool,
    /// Slice counts for --render, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = [32u32, 64, 128, 256, 512])]
    pub slices: Vec<u32>,
    /// No progress messages.
    #[arg(long, short)]
    pub quiet: bool,
}

/// The arguments of `halo4d render`.
#[derive(Args)]
pub struct RenderArgs {
    /// Scene file (JSON) [default: the built-in default scene].
    pub scene: Option<PathBuf>,
    /// The PNG to write [default: exports/<scene name>/<scene name>.png].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Image width in pixels.
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height in pixels.
    #[arg(long)]
    pub height: Option<u32>,
    /// How halos hide sheets: exact (per hit, the reference) or slices (paper 000).
    #[arg(long, value_enum)]
    pub mode: Option<RenderMode>,
    /// Slices for --mode slices.
    #[arg(long)]
    pub slices: Option<u32>,
    /// How surfaces are drawn: shaded (Phong over the w colours) or stipple (paper 003).
    #[arg(long, value_enum)]
    pub style: Option<Style>,
    /// A cross-eyed stereo pair side by side.
    #[arg(long)]
    pub stereo: bool,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
}

/// The arguments of `halo4d animate`.
#[derive(Args)]
pub struct AnimateArgs {
    /// Scene file (JSON) with an `animation`.
    #[arg(required_unless_present_any = ["assemble", "status"])]
    pub scene: Option<PathBuf>,
    /// Folder of the frames [default: exports/<scene name>/frames/].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Only these frames: A..B (A to B - 1), A..=B, or A.
    #[arg(long, value_name = "A..B")]
    pub frames: Option<FrameRange>,
    /// Only the frames whose index modulo N is I: task I of N of a batch engine's array
    /// (`--shard $SLURM_ARRAY_TASK_ID/N`, `--shard $JOB_COMPLETION_INDEX/N`).
    #[arg(long, value_name = "I/N")]
    pub shard: Option<Shard>,
    /// Picture width in pixels [default: the scene's render.width].
    #[arg(long)]
    pub width: Option<u32>,
    /// Picture height in pixels [default: the scene's render.height].
    #[arg(long)]
    pub height: Option<u32>,
    /// Write each frame's .glb too (frame-00042.glb).
    #[arg(long)]
    pub glb: bool,
    /// No progress output.
    #[arg(long, short)]
    pub quiet: bool,
    /// Instead: check that every frame of the folder DIR is done and verified (else
    /// list those that are not), write frames.jsonl and the animated PNG animation.png,
    /// and print the ffmpeg command line for an MP4.
    #[arg(long, value_name = "DIR", conflicts_with_all = ["scene", "status", "frames", "shard", "glb", "out"])]
    pub assemble: Option<PathBuf>,
    /// Instead: print where the frames of the folder DIR stand (done, failed, missing).
    #[arg(long, value_name = "DIR", conflicts_with_all = ["scene", "frames", "shard", "glb", "out"])]
    pub status: Option<PathBuf>,
}

/// The arguments of `halo4d gallery`.
#[derive(Args)]
pub struct GalleryArgs {
    /// The folder of scene files.
    #[arg(default_value = "fixtures/figures")]
    pub figures: PathBuf,
    /// The gallery's folder.
    #[arg(long, default_value = "exports/gallery")]
    pub out: PathBuf,
    /// No progress output.
    #[arg(long, short)]
    pub quiet: bool,
}

/// The arguments of `halo4d view`.
#[derive(Args)]
pub struct ViewArgs {
    /// Scene file (JSON) [default: the built-in default scene].
    pub scene: Option<PathBuf>,
    /// The scene file to write with the view found; without it, nothing is written.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
}

/// The arguments of `halo4d check`.
#[derive(Args)]
pub struct CheckArgs {
    /// A .glb (every mesh with `halo` extras) or legacy .vtk (with `surface_vertices`
    /// field data) file, or a folder with one scene .glb, as `halo4d build` writes them; or
    /// any tetrahedral mesh: legacy .vtk, .vtu, Gmsh .msh (2.2, 4.1), Medit .mesh, TetGen
    /// .node/.ele.
    #[arg(value_name = "FILE|DIR")]
    pub file: PathBuf,
    /// Print everything found as one JSON object (the verdict as `passes` and `failures`)
    /// instead of the tables.
    #[arg(long)]
    pub json: bool,
    /// Write the checked mesh (one without halo4d's layout) to this .vtu, each cell with its
    /// faults as the cell field `fault` (its bits: `Fault::legend`), and its dihedral angles
    /// and radius ratio.
    #[arg(long, value_name = "OUT.vtu", help = mark_help())]
    pub mark: Option<PathBuf>,
}

/// `--mark`'s help, its bits listed from the one declaration of the faults.
fn mark_help() -> String {
    format!(
        "Write the checked mesh (one without halo4d's layout) to this .vtu, each cell with its faults as the cell field `fault` (bits: {}), and its dihedral angles and radius ratio",
        halo4d::certify::Fault::legend()
    )
}

/// The arguments of `halo4d slice`.
#[derive(Args)]
pub struct SliceArgs {
    /// Scene file (JSON) [default: the built-in default scene].
    pub scene: Option<PathBuf>,
    /// The direction n as x,y,z,w in the surfaces' own coordinates, any nonzero length
    /// [default: the scene's `slicing.direction`, else the direction the scene's view turns
    /// onto w].
    #[arg(long, value_name = "X,Y,Z,W", allow_hyphen_values = true, value_parser = direction)]
    pub direction: Option<[f64; 4]>,
    /// Evenly spaced stills to add, between the lowest and the highest critical level
    /// [default: the scene's `slicing.levels`, else 0].
    #[arg(long)]
    pub levels: Option<usize>,
    /// Tilt the direction by this many degrees (towards the diagonal of its hyperplane's
    /// frame), to make the height a Morse function [default: the scene's
    /// `slicing.perturb`, else 0].
    #[arg(long, value_name = "DEGREES")]
    pub perturb: Option<f64>,
    /// A film of this many frames through the levels, from each surface's lowest point to
    /// its highest (<name>-film.png, an animated PNG), each frame checked against its
    /// interval [default: the scene's `slicing.film`, else none].
    #[arg(long, value_name = "FRAMES")]
    pub film: Option<u32>,
    /// Output folder [default: exports/<scene name>/motion/].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// No progress messages.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Four comma-separated numbers.
fn direction(s: &str) -> Result<[f64; 4], String> {
    let numbers: Vec<f64> = s
        .split(',')
        .map(|x| {
            x.trim()
                .parse::<f64>()
                .map_err(|_| format!("`{}` is not a number; give four numbers x,y,z,w", x.trim()))
        })
        .collect::<Result<_, _>>()?;
    numbers
        .try_into()
        .map_err(|v: Vec<f64>| format!("{} numbers; give four: x,y,z,w", v.len()))
}

/// A `--timeout`: a positive, finite number of seconds.
fn seconds(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(s) if s.is_finite() && s > 0.0 && s <= 1e9 => Ok(s),
        _ => Err(format!(
            "`{text}` is not a number of seconds above 0 (e.g. --timeout 60 or --timeout 0.5)"
        )),
    }
}
