//! The interactive window: an orbit camera around the scene, keys for the settings, the
//! settings and frame time in the title.
//!
//! Drag with the left button to turn (azimuth, elevation), wheel to zoom, `R` to reset the
//! camera (the title shows it, in `halo4d render`'s terms), `S` to cycle the slice count
//! (64, 128, 256, 512), `M` to switch between the grid and view-slice modes, `H` halos, `C`
//! curves, `O` silhouettes (outlines), `T` transparency, `W` colour by w, `Escape` or `Q`
//! to quit.

use super::{Asset, Gpu, HaloMode, Renderer, SLICE_COUNTS, ViewSettings, ViewerError};
use std::sync::Arc;
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

/// The window's help, printed when it opens.
pub const HELP: &str = "drag: turn | wheel: zoom | R: reset camera | S: slices | M: grid/view mode | H: halos | C: curves | O: silhouettes | T: transparency | W: colour by w | Q/Esc: quit";

/// Opens a window on `asset` with `settings` (its size the window's first size) and runs
/// until it is closed.
pub fn run(asset: Asset, settings: ViewSettings) -> Result<(), ViewerError> {
    settings.check()?;
    let event_loop = EventLoop::new()
        .map_err(|e| ViewerError::NoAdapter(format!("no display to open a window on: {e}")))?;
    let mut app = App {
        asset,
        initial: settings,
        settings,
        state: None,
        error: None,
        drag: None,
        cursor: (0.0, 0.0),
        last_ms: 0.0,
        last_good: settings,
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

struct App {
    asset: Asset,
    initial: ViewSettings,
    settings: ViewSettings,
    state: Option<State>,
    error: Option<ViewerError>,
    drag: Option<(f64, f64)>,
    cursor: (f64, f64),
    last_ms: f64,
    /// The last settings that rendered.
    last_good: ViewSettings,
}

impl App {
    fn open(&mut self, event_loop: &ActiveEventLoop) -> Result<State, ViewerError> {
        let attributes = Window::default_attributes()
            .with_title(format!("halo4d-view: {}", self.asset.name))
            .with_inner_size(winit::dpi::PhysicalSize::new(
                self.settings.width,
                self.settings.height,
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
        let renderer = Renderer::new(&gpu, &self.asset, config.format)?;
        Ok(State {
            window,
            surface,
            gpu,
            config,
            renderer,
        })
    }

    fn redraw(&mut self) -> Result<(), ViewerError> {
        let Some(state) = &mut self.state else {
            return Ok(());
        };
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
        self.settings.width = state.config.width;
        self.settings.height = state.config.height;
        let view = frame.texture.create_view(&Default::default());
        let times = match state.renderer.render(&state.gpu, &view, &self.settings) {
            Ok(times) => times,
            // A setting this GPU cannot do (a grid too large, say): back to the last one
            // that rendered, with the reason in the title; anything else ends the viewer.
            Err(e @ (ViewerError::TooLarge { .. } | ViewerError::Setting(_))) => {
                self.settings = ViewSettings {
                    width: self.settings.width,
                    height: self.settings.height,
                    ..self.last_good
                };
                state.window.set_title(&format!("halo4d-view: {e}"));
                return Ok(());
            }
            Err(e) => return Err(e),
        };
        state.gpu.queue.present(frame);
        self.last_good = self.settings;
        self.last_ms = times.frame_ms;
        let s = &self.settings;
        let on = |b: bool| if b { "on" } else { "off" };
        state.window.set_title(&format!(
            "halo4d-view: {} | {} {} slices | {} spp | halos {} | curves {} | silhouettes {} | {} | colour {} | azimuth {:.0} elevation {:.0} distance {:.2} | {:.1} ms{}",
            self.asset.name,
            s.mode.name(),
            s.slices,
            s.samples,
            on(s.halos),
            on(s.curves),
            on(s.silhouettes),
            if s.transparent { "transparent" } else { "opaque" },
            if s.colour_by_w { "by w" } else { "grey" },
            s.camera.azimuth,
            s.camera.elevation,
            s.camera.distance,
            self.last_ms,
            times
                .grid_ms
                .map_or_else(String::new, |g| format!(" (grid built in {g:.0} ms)")),
        ));
        Ok(())
    }

    /// Applies a key; whether it changed anything.
    fn key(&mut self, key: &Key, event_loop: &ActiveEventLoop) -> bool {
        let s = &mut self.settings;
        match key {
            Key::Named(NamedKey::Escape) => event_loop.exit(),
            Key::Character(c) => match c.to_lowercase().as_str() {
                "q" => event_loop.exit(),
                "r" => s.camera = self.initial.camera,
                "s" => {
                    let i = SLICE_COUNTS.iter().position(|&n| n == s.slices);
                    s.slices = SLICE_COUNTS[i.map_or(0, |i| (i + 1) % SLICE_COUNTS.len())];
                }
                "m" => {
                    s.mode = match s.mode {
                        HaloMode::Grid => HaloMode::View,
                        HaloMode::View => HaloMode::Grid,
                    }
                }
                "h" => s.halos = !s.halos,
                "c" => s.curves = !s.curves,
                "o" => s.silhouettes = !s.silhouettes,
                "t" => s.transparent = !s.transparent,
                "w" => s.colour_by_w = !s.colour_by_w,
                _ => return false,
            },
            _ => return false,
        }
        true
    }
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
            WindowEvent::CloseRequested => event_loop.exit(),
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
            }
            WindowEvent::CursorMoved { position, .. } => {
                self.cursor = (position.x, position.y);
                if let Some((x, y)) = self.drag {
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
                let c = &mut self.settings.camera;
                c.distance = (c.distance * 0.9f64.powf(steps)).clamp(0.2, 50.0);
                redraw = true;
            }
            WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Pressed => {
                redraw = self.key(&event.logical_key, event_loop);
            }
            _ => {}
        }
        if redraw && let Some(state) = &self.state {
            state.window.request_redraw();
        }
    }
}
