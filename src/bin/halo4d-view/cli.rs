//! `halo4d-view`'s flags.

use clap::Parser;
use halo4d::limits::FINITE;
use halo4d::render::{Colormap, Style};
use halo4d::viewer::{self, HaloMode};
use std::path::PathBuf;

#[derive(Parser, Debug)]
#[command(
    name = "halo4d-view",
    version,
    about = "Explore a scene in 4D (SCENE.json, or the default scene), or view a scene's .glb (written by `halo4d build`): surfaces, halos and curves on the GPU",
    after_help = viewer::window::HELP
)]
pub struct Args {
    /// A scene file (turned in 4D, its halos rebuilt on the GPU for every view), or a
    /// scene's .glb as `halo4d build` writes it (turned in 3D); the default scene if none.
    pub file: Option<PathBuf>,
    /// Turn the scene's 4D view: PLANE=DEGREES added to the scene's angle of that plane
    /// (xy, xz, xw, yz, yw or zw; applied in that order, as in the scene file). Repeatable.
    #[arg(long, value_name = "PLANE=DEGREES", value_parser = parse_rotate, allow_hyphen_values = true)]
    pub rotate: Vec<(String, f64)>,
    /// Write the scene with the current 4D view and camera to OUT.json, which `halo4d build`
    /// turns into the verified asset of that view.
    #[arg(long, value_name = "OUT.json")]
    pub save_scene: Option<PathBuf>,
    /// Render offscreen (no window, no display) and write --screenshot.
    #[arg(long)]
    pub headless: bool,
    /// The PNG a headless run writes.
    #[arg(long, value_name = "OUT.png")]
    pub screenshot: Option<PathBuf>,
    /// Image (or first window) size, WIDTHxHEIGHT.
    #[arg(long, value_name = "WxH", default_value = "1024x1024", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Slices of the halo depth (64, 128, 256 or 512 in the window; 2 to 1024 here).
    #[arg(long, default_value_t = 256)]
    pub slices: u32,
    /// Samples per pixel (1, 4, 9 or 16; default 4 for --screenshot, as `halo4d render`,
    /// else 1).
    #[arg(long)]
    pub samples: Option<u32>,
    /// How the halo depth is sliced: once into a 3D grid, or per frame along the view.
    #[arg(long, value_enum, default_value_t = HaloMode::Grid)]
    pub mode: HaloMode,
    /// Camera azimuth in degrees (default: the scene's camera, else 35).
    #[arg(long, allow_negative_numbers = true)]
    pub azimuth: Option<f64>,
    /// Camera elevation in degrees, -89 to 89 (default: the scene's, else 25).
    #[arg(long, allow_negative_numbers = true)]
    pub elevation: Option<f64>,
    /// Eye distance in half-diagonals of the scene (default: the scene's, else fitted so
    /// that the surfaces fill the picture).
    #[arg(long)]
    pub distance: Option<f64>,
    /// Vertical field of view in degrees (default: the scene's, else 38).
    #[arg(long)]
    pub fov: Option<f64>,
    /// Orthographic instead of perspective.
    #[arg(long)]
    pub orthographic: bool,
    /// Halos hide nothing.
    #[arg(long)]
    pub no_halos: bool,
    /// Leave the curves out.
    #[arg(long)]
    pub no_curves: bool,
    /// Leave the silhouettes out.
    #[arg(long)]
    pub no_silhouettes: bool,
    /// Half-transparent surfaces.
    #[arg(long)]
    pub transparent: bool,
    /// One grey instead of colour by w.
    #[arg(long)]
    pub grey: bool,
    /// The colour scale of w.
    #[arg(long, value_enum, default_value_t = Colormap::Diverging)]
    pub colormap: Colormap,
    /// Shaded surfaces, or stipples (paper 003) on the first surface the halos leave
    /// visible, with the scene's render.stipple (default: the scene's render.style).
    #[arg(long, value_enum)]
    pub style: Option<Style>,
    /// Render a fixed orbit (and for a scene a 4D turn) for each mode and slice count (64,
    /// 128, 256, 512) offscreen, then in stipples in --mode at --slices, and print
    /// milliseconds per frame (with --style, that style's rows only).
    #[arg(long)]
    pub bench: bool,
    /// Frames per orbit for --bench.
    #[arg(long, default_value_t = 36)]
    pub frames: u32,
    /// Show the slice by the hyperplane of the scene's `slicing` (the one `halo4d slice`
    /// cuts along) at LEVEL, a height along its direction, over the surfaces (a scene only;
    /// in the window, `L` shows it at the middle and `,` `.` move it).
    #[arg(long, value_name = "LEVEL", allow_negative_numbers = true)]
    pub hyperplane: Option<f64>,
    /// Render with the CPU renderer's exact mode too, and print for each mode and slice
    /// count the share of covered pixels where what is visible differs.
    #[arg(long)]
    pub compare: bool,
}

pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("`{s}` is not WIDTHxHEIGHT, e.g. 1920x1080"))?;
    let n = |v: &str| {
        v.trim()
            .parse::<u32>()
            .map_err(|_| format!("`{v}` in `{s}` is not a whole number of pixels"))
    };
    Ok((n(w)?, n(h)?))
}

pub fn parse_rotate(s: &str) -> Result<(String, f64), String> {
    let (plane, degrees) = s
        .split_once('=')
        .ok_or_else(|| format!("`{s}` is not PLANE=DEGREES, e.g. xw=20"))?;
    let plane = plane.trim().to_ascii_lowercase();
    if halo4d::view::Rotation4::default()
        .angle_mut(&plane)
        .is_none()
    {
        return Err(format!(
            "`{plane}` is not a plane of R^4: use xy, xz, xw, yz, yw or zw"
        ));
    }
    let degrees: f64 = degrees
        .trim()
        .parse()
        .map_err(|_| format!("`{degrees}` in `{s}` is not a number of degrees"))?;
    FINITE
        .check("DEGREES", degrees)
        .map_err(|e| format!("`{s}`: {e}"))?;
    Ok((plane, degrees))
}
