//! The interactive window: an orbit camera around the scene and, for a scene file, its 4D
//! view turned live (the halos rebuilt on the GPU when the 4D view changes, the exact curves
//! computed on the CPU in the background once it stops); keys for the settings; the
//! settings, the 4D view and the frame time in the title.
//!
//! Drag with the left button to turn the camera (azimuth, elevation), wheel to zoom, `R` to
//! reset the camera (the title shows it, in `halo4d render`'s terms), `S` to cycle the
//! slice count (64, 128, 256, 512), `M` to switch between the grid and view-slice modes,
//! `H` halos, `C` curves, `O` silhouettes (outlines), `T` transparency, `W` colour by w,
//! `D` shaded surfaces or stipples (dots; the stipples are made on the CPU in the
//! background the first time, the title says so meanwhile), `Escape` or `Q` to quit. In 4D
//! (a scene file): Shift + drag turns the direction of the drag on the screen towards w
//! (Hanson's rolling ball), its frames sliced at 64 until it stops; the keys `1` to `6`
//! turn the planes xy, xz, xw, yz, yw and zw by 15 degrees (with Shift, back); `[` and `]`
//! move the surfaces along w; `P` switches the 4D projection between orthographic and
//! perspective; `V` resets the 4D view; `F` writes the current view as a scene file
//! (`exports/views/<name>-<k>.json`) and `B` builds it in the background
//! (`exports/<name>-<k>/`), its verification in the title; `L` shows or hides the slice by
//! the hyperplane of the scene's `slicing` (as `halo4d slice` cuts: the curves where the
//! surfaces cross a level of the height along that direction, drawn over them in magenta;
//! hidden, it keeps its level) and `,` and `.` move the level down and up by 1/64 of the
//! surfaces' range of heights (with Shift, 1/640); the title names the level, its number of
//! curves and the critical levels either side of it. The title shows the 4D view in the
//! scene file's terms.

use super::{
    Gpu, HaloMode, Hyperplane, Renderer, SLICE_COUNTS, Source, StippleSet, ViewSettings,
    ViewerError,
};
use crate::intersect::Curves;
use crate::progress::{Cancel, Job, Silent};
use crate::render::Style;
use crate::scene::Scene;
use crate::view::{Projection, View};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::mpsc::{Receiver, channel};
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::{Key, KeyCode, ModifiersState, NamedKey, PhysicalKey};
use winit::window::{Window, WindowId};

/// The window's help, printed when it opens.
pub const HELP: &str = "drag: turn | wheel: zoom | R: reset camera | S: slices | M: grid/view mode | H: halos | C: curves | O: silhouettes | T: transparency | W: colour by w | D: shaded/stipples | Q/Esc: quit\n4D (a scene file): Shift+drag: turn towards w | 1-6: turn xy xz xw yz yw zw by 15 degrees (Shift: back) | [ ]: move along w | P: 4D perspective/orthographic | V: reset the 4D view | F: save the view as a scene | B: build the saved view | L: slice by the hyperplane | , .: move it (Shift: finely)";

/// Degrees a plane key turns.
const STEP: f64 = 15.0;
/// Degrees of a 4D or 3D turn per pixel dragged.
const DRAG: f64 = 0.4;
/// The share of the surfaces' range of heights a slice key moves the hyperplane (with
/// Shift, a tenth of it).
const SLICE_STEP: f64 = 1.0 / 64.0;

/// Opens a window on `source` with `settings` (its size the window's first size), a model
/// in the 4D `view` (its scene's when `None`) with the slice by its hyperplane at level
/// `hyperplane` shown where one is given, and runs until it is closed.
pub fn run(
    source: Source,
    view: Option<View>,
    settings: ViewSettings,
    hyperplane: Option<f64>,
) -> Result<(), ViewerError> {
    settings.check()?;
    let hyperplane = hyperplane.map(|c| source.hyperplane(Some(c))).transpose()?;
    let event_loop = EventLoop::new()
        .map_err(|e| ViewerError::NoAdapter(format!("no display to open a window on: {e}")))?;
    let view = match &source {
        Source::Model(m) => Some(view.unwrap_or(m.scene.view)),
        Source::Asset(_) => None,
    };
    let mut app = App {
        source,
        initial: settings,
        settings,
        initial_view: view,
        view,
        drawn_view: view,
        state: None,
        error: None,
        drag: None,
        cursor: (0.0, 0.0),
        modifiers: ModifiersState::default(),
        drawn_slices: settings.render.slices,
        last_ms: 0.0,
        turn_ms: None,
        last_good: settings,
        curves: CurveJob::default(),
        saved: None,
        saves: 0,
        build: None,
        work: Cancel::new(),
        search: None,
        note: String::new(),
        stipples: None,
        slice_shown: hyperplane.is_some(),
        hyperplane,
        slice_drawn: false,
    };
    event_loop
        .run_app(&mut app)
        .map_err(|e| ViewerError::Gpu(format!("the window's event loop failed: {e}")))?;
    app.error.map_or(Ok(()), Err)
}

struct State {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    gpu: Gpu,
    config: wgpu::SurfaceConfiguration,
    renderer: Renderer,
}

/// The exact curves of a view, computed on the CPU in the background: at most one job at a
/// time; one finished for a view no longer shown is dropped and the current view's started.
#[derive(Default)]
struct CurveJob {
    running: Option<Receiver<(View, Result<Curves, ViewerError>)>>,
    /// The view whose curves the renderer draws.
    shown: Option<View>,
}

struct App {
    source: Source,
    initial: ViewSettings,
    settings: ViewSettings,
    /// The 4D view it opened in, the one asked for, and the one drawn (a model only).
    initial_view: Option<View>,
    view: Option<View>,
    drawn_view: Option<View>,
    state: Option<State>,
    error: Option<ViewerError>,
    drag: Option<(f64, f64)>,
    cursor: (f64, f64),
    modifiers: ModifiersState,
    /// The slices the last frame was drawn with ([`slices_drawn`]).
    drawn_slices: u32,
    last_ms: f64,
    /// What the last 4D turn cost, while it is the frame's news.
    turn_ms: Option<f64>,
    /// The last settings that rendered.
    last_good: ViewSettings,
    curves: CurveJob,
    /// The last scene saved with `F`.
    saved: Option<(crate::scene::Scene, PathBuf)>,
    saves: u32,
    /// A build running in the background: its outcome in words.
    build: Option<Receiver<String>>,
    /// Stops the build and the view search running in the background when the window
    /// closes.
    work: Cancel,
    /// A view search running in the background (`A`): the view found, or why none.
    search: Option<Receiver<Result<crate::viewsearch::Found, String>>>,
    /// The last message for the title (a save, a build's outcome, a refused view).
    note: String,
    /// The stipples being made in the background, until the renderer has them.
    stipples: Option<Receiver<Result<StippleSet, ViewerError>>>,
    /// The hyperplane (made the first time `L` shows it, kept when it is hidden: its level
    /// and the surfaces' critical points) and whether its slice is shown.
    hyperplane: Option<Hyperplane>,
    slice_shown: bool,
    /// Whether the renderer draws the hyperplane's slice as it is now.
    slice_drawn: bool,
}

impl App {
    fn open(&mut self, event_loop: &ActiveEventLoop) -> Result<State, ViewerError> {
        let attributes = Window::default_attributes()
            .with_title(format!("halo4d-view: {}", self.source.name()))
            .with_inner_size(winit::dpi::PhysicalSize::new(
                self.settings.render.width,
                self.settings.render.height,
            ));
        let window = Arc::new(
            event_loop
                .create_window(attributes)
                .map_err(|e| ViewerError::NoAdapter(format!("cannot open a window: {e}")))?,
        );
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let surface = instance
            .create_surface(window.clone())
            .map_err(|e| ViewerError::NoAdapter(format!("cannot draw into the window: {e}")))?;
        let gpu = Gpu::with_instance(instance, Some(&surface))?;
        let size = window.inner_size();
        let mut config = surface
            .get_default_config(&gpu.adapter, size.width.max(1), size.height.max(1))
            .ok_or_else(|| ViewerError::NoAdapter("the GPU cannot draw into this window".into()))?;
        let caps = surface.get_capabilities(&gpu.adapter);
        if let Some(&srgb) = caps.formats.iter().find(|f| f.is_srgb()) {
            config.format = srgb;
        }
        surface.configure(&gpu.device, &config);
        let renderer = self
            .source
            .renderer(&gpu, self.view.as_ref(), false, config.format)?;
        Ok(State {
            window,
            surface,
            gpu,
            config,
            renderer,
        })
    }

    fn redraw(&mut self) -> Result<(), ViewerError> {
        self.turn()?;
        self.draw_slice()?;
        self.poll_curves()?;
        self.poll_jobs();
        self.poll_stipples()?;
        let turning = self.turning_in_4d();
        let Some(state) = &mut self.state else {
            return Ok(());
        };
        let making = self.settings.render.style == Style::Stipple && !state.renderer.has_stipples();
        let frame = match state.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(f)
            | wgpu::CurrentSurfaceTexture::Suboptimal(f) => f,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                state.surface.configure(&state.gpu.device, &state.config);
                state.window.request_redraw();
                return Ok(());
            }
            _ => return Ok(()),
        };
        self.settings.render.width = state.config.width;
        self.settings.render.height = state.config.height;
        let view = frame.texture.create_view(&Default::default());
        let mut drawn = self.settings;
        if making {
            drawn.render.style = Style::Shaded;
        }
        drawn.render.slices = slices_drawn(drawn.render.slices, turning);
        let times = match state.renderer.render(&state.gpu, &view, &drawn) {
            Ok(times) => times,
            // A setting this GPU cannot do (a grid too large, say): back to the last one
            // that rendered, with the reason in the title; anything else ends the viewer.
            Err(e @ (ViewerError::TooLarge { .. } | ViewerError::Setting(_))) => {
                let (width, height) = (self.settings.render.width, self.settings.render.height);
                self.settings = self.last_good;
                self.settings.render.width = width;
                self.settings.render.height = height;
                state.window.set_title(&format!("halo4d-view: {e}"));
                return Ok(());
            }
            Err(e) => return Err(e),
        };
        state.gpu.queue.present(frame);
        self.last_good = self.settings;
        self.drawn_slices = drawn.render.slices;
        self.last_ms = times.frame_ms;
        let title = self.title(&times, making);
        if let Some(state) = &self.state {
            state.window.set_title(&title);
        }
        Ok(())
    }

    /// A new 4D view: the surfaces and halos rebuilt on the GPU (a view that cannot be drawn
    /// is refused, the last one kept, the reason in the title).
    fn turn(&mut self) -> Result<(), ViewerError> {
        let Some(state) = &mut self.state else {
            return Ok(());
        };
        if let (Source::Model(model), Some(view)) = (&self.source, self.view)
            && self.drawn_view != Some(view)
        {
            match state.renderer.turn(&state.gpu, model, &view) {
                Ok(ms) => {
                    self.drawn_view = Some(view);
                    self.turn_ms = Some(ms);
                    self.slice_drawn = false;
                }
                Err(e @ ViewerError::View(_)) => {
                    self.note = e.to_string();
                    self.view = self.drawn_view;
                }
                Err(e) => return Err(e),
            }
        }
        Ok(())
    }

    /// Gives the renderer the hyperplane's slice in the drawn view, or none, when what it
    /// draws is not that.
    fn draw_slice(&mut self) -> Result<(), ViewerError> {
        let (Some(state), Some(view)) = (&mut self.state, self.drawn_view) else {
            return Ok(());
        };
        if !self.slice_drawn {
            let polylines = match &self.hyperplane {
                Some(h) if self.slice_shown => h.polylines(&view),
                _ => Vec::new(),
            };
            state.renderer.set_slice(&state.gpu, &polylines)?;
            self.slice_drawn = true;
        }
        Ok(())
    }

    /// The curves: the finished job's, when they are of the view drawn; a new job when the
    /// drawn view has none, none is running and the curves are shown.
    fn poll_curves(&mut self) -> Result<(), ViewerError> {
        let Some(state) = &mut self.state else {
            return Ok(());
        };
        if let Some(rx) = &self.curves.running
            && let Ok((view, curves)) = rx.try_recv()
        {
            self.curves.running = None;
            if Some(view) == self.drawn_view {
                match curves {
                    Ok(curves) => state.renderer.set_curves(&state.gpu, &curves)?,
                    // Drawn without curves, the reason in the title.
                    Err(e) => self.note = format!("no curves: {e}"),
                }
                self.curves.shown = Some(view);
            }
        }
        if let (Source::Model(model), Some(view)) = (&self.source, self.drawn_view)
            && self.settings.render.curves
            && self.curves.running.is_none()
            && self.curves.shown != Some(view)
        {
            let (tx, rx) = channel();
            let (model, window) = (Arc::clone(model), Arc::clone(&state.window));
            std::thread::spawn(move || {
                let _ = tx.send((view, model.curves(&view)));
                window.request_redraw();
            });
            self.curves.running = Some(rx);
        }
        Ok(())
    }

    /// The outcome of a build or a view search running in the background, when done.
    fn poll_jobs(&mut self) {
        if let Some(rx) = &self.build
            && let Ok(outcome) = rx.try_recv()
        {
            self.note = outcome;
            self.build = None;
        }
        if let Some(rx) = &self.search
            && let Ok(found) = rx.try_recv()
        {
            self.search = None;
            match found {
                Ok(found) => {
                    if let Some(view) = &mut self.view {
                        view.rotation = found.rotation;
                    }
                    self.settings.camera.azimuth = found.azimuth;
                    self.settings.camera.elevation = found.elevation;
                    self.note = format!(
                        "view search: {:.2} of the curves in view (was {:.2})",
                        found.visible_curve_share, found.start_share
                    );
                    if let Some(state) = &self.state {
                        state.window.request_redraw();
                    }
                }
                Err(e) => self.note = e,
            }
        }
    }

    /// The stipples: made once, in the background; shaded until they are ready, and back to
    /// shaded, the reason in the title, where the source has no 4D mesh.
    fn poll_stipples(&mut self) -> Result<(), ViewerError> {
        let Some(state) = &mut self.state else {
            return Ok(());
        };
        let stippled = self.settings.render.style == Style::Stipple;
        if stippled && !state.renderer.has_stipples() {
            match &self.stipples {
                None => {
                    let (tx, rx) = channel();
                    let (source, window) = (self.source.clone(), Arc::clone(&state.window));
                    let st = self.settings.render.stipple;
                    std::thread::spawn(move || {
                        let _ = tx.send(source.stipples(st.count, st.seed));
                        window.request_redraw();
                    });
                    self.stipples = Some(rx);
                }
                Some(rx) => {
                    if let Ok(made) = rx.try_recv() {
                        self.stipples = None;
                        match made {
                            Ok(set) => state.renderer.set_stipples(&state.gpu, &set)?,
                            Err(e) => {
                                self.note = e.to_string();
                                self.settings.render.style = Style::Shaded;
                            }
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// The window's title: the settings, the camera, the frame's time, the 4D view.
    fn title(&self, times: &super::FrameTimes, making: bool) -> String {
        let Some(state) = &self.state else {
            return String::new();
        };
        let s = &self.settings;
        let placement =
            state
                .renderer
                .asset()
                .placement(&s.camera, s.render.width, s.render.height);
        let on = |b: bool| if b { "on" } else { "off" };
        let four = match self.drawn_view {
            None if self.note.is_empty() => String::new(),
            None => format!(" | {}", self.note),
            Some(v) => format!(
                " | 4D {}{}{}{} | {}",
                describe(&v),
                self.turn_ms
                    .map_or_else(String::new, |ms| format!(" (halos rebuilt in {ms:.0} ms)")),
                match &self.hyperplane {
                    Some(h) if self.slice_shown => format!(" | {}", h.describe()),
                    _ => String::new(),
                },
                if self.note.is_empty() {
                    String::new()
                } else {
                    format!(" | {}", self.note)
                },
                if !s.render.curves || self.curves.shown == Some(v) {
                    "settled"
                } else {
                    "computing the curves"
                }
            ),
        };
        format!(
            "halo4d-view: {} | {} | {} {} | {} spp | halos {} | curves {} | silhouettes {} | {} | colour {} | azimuth {:.0} elevation {:.0} distance {:.2}{} | {:.1} ms{}{four}",
            self.source.name(),
            match (s.render.style, making) {
                (Style::Shaded, _) => "shaded",
                (Style::Stipple, false) => "stipples",
                (Style::Stipple, true) => "making the stipples",
            },
            s.mode.name(),
            if self.drawn_slices == s.render.slices {
                format!("{} slices", s.render.slices)
            } else {
                format!(
                    "{} slices while turning ({} when still)",
                    self.drawn_slices, s.render.slices
                )
            },
            s.render.samples,
            on(s.render.halos),
            on(s.render.curves),
            on(s.render.silhouettes),
            if s.transparent {
                "transparent"
            } else {
                "opaque"
            },
            if s.colour_by_w { "by w" } else { "grey" },
            s.camera.azimuth,
            s.camera.elevation,
            placement.distance,
            if placement.fitted { " fitted" } else { "" },
            self.last_ms,
            times
                .grid_ms
                .map_or_else(String::new, |g| format!(" (grid built in {g:.0} ms)")),
        )
    }

    /// Applies a key; whether it changed anything.
    fn key(&mut self, key: &Key, physical: PhysicalKey, event_loop: &ActiveEventLoop) -> bool {
        if self.key_4d(key, physical) {
            return true;
        }
        let s = &mut self.settings;
        match key {
            Key::Named(NamedKey::Escape) => event_loop.exit(),
            Key::Character(c) => match c.to_lowercase().as_str() {
                "q" => event_loop.exit(),
                "r" => s.camera = self.initial.camera,
                "s" => {
                    let i = SLICE_COUNTS.iter().position(|&n| n == s.render.slices);
                    s.render.slices = SLICE_COUNTS[i.map_or(0, |i| (i + 1) % SLICE_COUNTS.len())];
                }
                "m" => {
                    s.mode = match s.mode {
                        HaloMode::Grid => HaloMode::View,
                        HaloMode::View => HaloMode::Grid,
                    }
                }
                "h" => s.render.halos = !s.render.halos,
                "c" => s.render.curves = !s.render.curves,
                "o" => s.render.silhouettes = !s.render.silhouettes,
                "t" => s.transparent = !s.transparent,
                "w" => s.colour_by_w = !s.colour_by_w,
                "d" => {
                    s.render.style = match s.render.style {
                        Style::Shaded => Style::Stipple,
                        Style::Stipple => Style::Shaded,
                    }
                }
                _ => return false,
            },
            _ => return false,
        }
        true
    }

    /// Applies a key of the 4D view; whether it was one (a model only).
    fn key_4d(&mut self, key: &Key, physical: PhysicalKey) -> bool {
        let (Source::Model(model), Some(view)) = (&self.source, &mut self.view) else {
            return false;
        };
        let sign = if self.modifiers.shift_key() {
            -1.0
        } else {
            1.0
        };
        let plane = match physical {
            PhysicalKey::Code(KeyCode::Digit1) => Some("xy"),
            PhysicalKey::Code(KeyCode::Digit2) => Some("xz"),
            PhysicalKey::Code(KeyCode::Digit3) => Some("xw"),
            PhysicalKey::Code(KeyCode::Digit4) => Some("yz"),
            PhysicalKey::Code(KeyCode::Digit5) => Some("yw"),
            PhysicalKey::Code(KeyCode::Digit6) => Some("zw"),
            _ => None,
        };
        if let Some(plane) = plane {
            let angle = view.rotation.angle_mut(plane).expect("a plane of R^4");
            *angle = crate::view::wrap_degrees(*angle + sign * STEP);
            self.note.clear();
            return true;
        }
        let fine = if self.modifiers.shift_key() { 0.1 } else { 1.0 };
        let step = match physical {
            PhysicalKey::Code(KeyCode::Comma) => Some(-fine),
            PhysicalKey::Code(KeyCode::Period) => Some(fine),
            _ => None,
        };
        if let Some(step) = step {
            if let Some(plane) = self.hyperplane.as_mut().filter(|_| self.slice_shown) {
                plane.step(step * SLICE_STEP);
                self.slice_drawn = false;
            } else {
                self.note = "no slice shown: press L first".into();
            }
            return true;
        }
        let Key::Character(c) = key else {
            return false;
        };
        let reach = model.radius_4d();
        match c.to_lowercase().as_str() {
            "l" => {
                if self.hyperplane.is_none() {
                    match model.hyperplane(None) {
                        Ok(plane) => {
                            self.note = plane.notes.join("; ");
                            self.hyperplane = Some(plane);
                        }
                        Err(e) => self.note = format!("no slice: {e}"),
                    }
                }
                self.slice_shown = !self.slice_shown && self.hyperplane.is_some();
                self.slice_drawn = false;
                return true;
            }
            "[" => view.translation[3] -= 0.05 * reach,
            "]" => view.translation[3] += 0.05 * reach,
            "v" => *view = self.initial_view.expect("a model has a view"),
            "p" => {
                view.projection = match view.projection {
                    Projection::Perspective { .. } => Projection::Orthographic,
                    Projection::Orthographic => match model.scene.view.projection {
                        p @ Projection::Perspective { .. } => p,
                        // The eye three 4D radii away from the hyperplane w = 0.
                        Projection::Orthographic => Projection::Perspective {
                            eye_distance: 3.0 * reach,
                        },
                    },
                }
            }
            "f" => {
                let (scene, view) = (model.scene.clone(), *view);
                self.save_view(&scene, view);
                return true;
            }
            "a" => {
                let (scene, view) = (model.scene.clone(), *view);
                self.start_search(scene, view);
                return true;
            }
            "b" => {
                self.start_build();
                return true;
            }
            _ => return false,
        }
        self.note.clear();
        true
    }

    /// `F`: saves the scene in the view and camera shown to `exports/views/`, for `B`.
    fn save_view(&mut self, scene: &Scene, view: View) {
        let camera = self.settings.camera;
        self.saves += 1;
        let path =
            PathBuf::from("exports/views").join(format!("{}-{}.json", scene.name, self.saves));
        self.note = match std::fs::create_dir_all("exports/views")
            .map_err(|e| ViewerError::Write {
                path: "exports/views".into(),
                message: e.to_string(),
            })
            .and_then(|()| super::save_scene(scene, &view, &camera, &path))
        {
            Ok(scene) => {
                let note = format!("saved {}", path.display());
                self.saved = Some((scene, path));
                note
            }
            Err(e) => e.to_string(),
        };
    }

    /// `A`: searches, on a thread of its own, the view that shows the most of the curves,
    /// from the view and camera shown.
    fn start_search(&mut self, mut scene: Scene, view: View) {
        if self.search.is_some() {
            self.note = "a view search is running".into();
            return;
        }
        scene.view = view;
        scene.camera.azimuth = self.settings.camera.azimuth;
        scene.camera.elevation = self.settings.camera.elevation;
        let window = self.state.as_ref().map(|s| Arc::clone(&s.window));
        let (tx, rx) = channel();
        self.note = "searching the view that shows the most of the curves".into();
        let cancel = self.work.clone();
        std::thread::spawn(move || {
            let job = Job::new(&Silent, &cancel);
            let found = crate::viewsearch::search(&scene, job).map_err(|e| e.to_string());
            let _ = tx.send(found);
            if let Some(w) = window {
                w.request_redraw();
            }
        });
        self.search = Some(rx);
    }

    /// `B`: builds the scene last saved (`F`) into `exports/`, on a thread of its own.
    fn start_build(&mut self) {
        let Some((scene, path)) = self.saved.clone() else {
            self.note = "nothing saved to build: press F first".into();
            return;
        };
        if self.build.is_some() {
            self.note = "a build is running".into();
            return;
        }
        let out = PathBuf::from("exports").join(&scene.name);
        let window = self.state.as_ref().map(|s| Arc::clone(&s.window));
        let (tx, rx) = channel();
        self.note = format!("building {}", path.display());
        let cancel = self.work.clone();
        std::thread::spawn(move || {
            let job = Job::new(&Silent, &cancel);
            let outcome = match crate::pipeline::build(&scene, &out, job) {
                Ok(report) if report.verified => {
                    format!("built {} from {}: verified", out.display(), path.display())
                }
                Ok(report) => format!(
                    "built {}: NOT verified: {}",
                    out.display(),
                    report.failures.join("; ")
                ),
                Err(e) => format!("the build of {} failed: {e}", path.display()),
            };
            let _ = tx.send(outcome);
            if let Some(w) = window {
                w.request_redraw();
            }
        });
        self.build = Some(rx);
    }

    /// Whether a Shift drag is turning the scene in 4D (every frame rebuilds the halos).
    fn turning_in_4d(&self) -> bool {
        self.drag.is_some() && self.modifiers.shift_key() && self.view.is_some()
    }

    /// A drag of (dx, dy) pixels with Shift: the 4D rolling ball.
    fn roll(&mut self, dx: f64, dy: f64) -> bool {
        let (Some(view), Some(state)) = (&mut self.view, &self.state) else {
            return false;
        };
        let asset = state.renderer.asset();
        let (camera, width, height) = (
            &self.settings.camera,
            self.settings.render.width,
            self.settings.render.height,
        );
        let placement = asset.placement(camera, width, height);
        let Ok(camera) = crate::render::camera::Camera::new(camera, &placement, width, height, 0.0)
        else {
            return false;
        };
        let towards = camera.right * dx - camera.up * dy;
        if towards.length() == 0.0 {
            return false;
        }
        view.rotation = view.rotation.rolled(towards, DRAG * dx.hypot(dy));
        self.note.clear();
        true
    }
}

/// The slices a frame is drawn with: while a drag turns the scene in 4D, at most the
/// fewest the viewer offers (every frame then slices the rebuilt halos' depth again, in the
/// grid mode or along the view; at 1024 x 768 on lavapipe a 4D turn takes 100 ms a frame at
/// 64 slices and 220 ms at 256), and the settings' own once it stops.
fn slices_drawn(slices: u32, turning: bool) -> u32 {
    if turning {
        slices.min(SLICE_COUNTS[0])
    } else {
        slices
    }
}

/// A 4D view in the scene file's terms.
fn describe(v: &View) -> String {
    let angles: Vec<String> = v
        .rotation
        .planes()
        .iter()
        // Whole degrees, with no "-0".
        .map(|(name, a)| format!("{name} {}", a.round() + 0.0))
        .collect();
    let [x, y, z, w] = v.translation;
    let shift = if v.translation == [0.0; 4] {
        String::new()
    } else {
        format!(" translation [{x:.2}, {y:.2}, {z:.2}, {w:.2}]")
    };
    let projection = match v.projection {
        Projection::Orthographic => "orthographic".to_string(),
        Projection::Perspective { eye_distance } => format!("perspective eye {eye_distance:.2}"),
    };
    format!("{}{shift} {projection}", angles.join(" "))
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.state.is_some() {
            return;
        }
        match self.open(event_loop) {
            Ok(state) => {
                state.window.request_redraw();
                self.state = Some(state);
            }
            Err(e) => {
                self.error = Some(e);
                event_loop.exit();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let mut redraw = false;
        match event {
            WindowEvent::CloseRequested => {
                self.work.cancel();
                event_loop.exit();
            }
            WindowEvent::Resized(size) => {
                if let Some(state) = &mut self.state
                    && size.width > 0
                    && size.height > 0
                {
                    state.config.width = size.width;
                    state.config.height = size.height;
                    state.surface.configure(&state.gpu.device, &state.config);
                    redraw = true;
                }
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.redraw() {
                    self.error = Some(e);
                    event_loop.exit();
                }
            }
            WindowEvent::MouseInput {
                state: pressed,
                button: MouseButton::Left,
                ..
            } => {
                self.drag = (pressed == ElementState::Pressed).then_some(self.cursor);
                redraw = self.drawn_slices != self.settings.render.slices;
            }
            WindowEvent::ModifiersChanged(m) => {
                self.modifiers = m.state();
                redraw = self.drawn_slices != self.settings.render.slices;
            }
            WindowEvent::CursorMoved { position, .. } => {
                self.cursor = (position.x, position.y);
                if let Some((x, y)) = self.drag
                    && self.modifiers.shift_key()
                    && self.view.is_some()
                {
                    redraw = self.roll(position.x - x, position.y - y);
                    self.drag = Some(self.cursor);
                } else if let Some((x, y)) = self.drag {
                    let c = &mut self.settings.camera;
                    c.azimuth = (c.azimuth - (position.x - x) * 0.4).rem_euclid(360.0);
                    c.elevation = (c.elevation + (position.y - y) * 0.4).clamp(-89.0, 89.0);
                    self.drag = Some(self.cursor);
                    redraw = true;
                }
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let steps = match delta {
                    MouseScrollDelta::LineDelta(_, y) => f64::from(y),
                    MouseScrollDelta::PixelDelta(p) => p.y / 40.0,
                };
                // The wheel zooms from where the eye stands, fitted or not.
                if let Some(state) = &self.state {
                    let s = &self.settings;
                    let from = state
                        .renderer
                        .asset()
                        .placement(&s.camera, s.render.width, s.render.height)
                        .distance;
                    self.settings.camera.distance =
                        Some((from * 0.9f64.powf(steps)).clamp(0.2, 50.0));
                    redraw = true;
                }
            }
            // A held key repeats only the steps (a 4D turn, a move along w); a toggle or a
            // cycle taken twice from one press (an auto-repeat under load) would skip a state.
            WindowEvent::KeyboardInput { event, .. }
                if event.state == ElementState::Pressed
                    && (!event.repeat || is_step(&event.logical_key, event.physical_key)) =>
            {
                redraw = self.key(&event.logical_key, event.physical_key, event_loop);
            }
            _ => {}
        }
        if redraw && let Some(state) = &self.state {
            state.window.request_redraw();
        }
    }
}

/// Whether a key is a step that holding it repeats: a 4D turn (1 to 6) or a move along w ([ ]).
fn is_step(key: &Key, physical: PhysicalKey) -> bool {
    matches!(
        physical,
        PhysicalKey::Code(
            KeyCode::Digit1
                | KeyCode::Digit2
                | KeyCode::Digit3
                | KeyCode::Digit4
                | KeyCode::Digit5
                | KeyCode::Digit6
        )
    ) || matches!(key, Key::Character(c) if c.as_str() == "[" || c.as_str() == "]")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_4d_drag_draws_the_fewest_slices_and_stillness_the_settings_own() {
        for n in SLICE_COUNTS {
            assert_eq!(slices_drawn(n, false), n);
            assert_eq!(slices_drawn(n, true), 64);
        }
    }
}
