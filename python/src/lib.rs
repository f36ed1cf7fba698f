//! halo4d from Python (`import halo4d`): scenes read as the command line reads them, built
//! once sampled for any number of views, and the results as NumPy arrays.
//!
//! Every array is made in Rust in one pass over the build's own data, when it is asked for
//! (`built.surfaces[0].positions` twice is two arrays with the same values), never by a
//! loop over elements in Python: a `memcpy` of the build's vector where it keeps the array
//! as such; the halo's tetrahedra put in the files' vertex order, and each curve's points
//! gathered from its point records, in one loop. The work runs with the GIL released, on a
//! thread of its own, while the calling thread waits in slices of 50 ms, calls the
//! `progress` function it was given with each of the work's events and checks for signals:
//! Ctrl-C cancels the work (`halo4d::progress::Cancel`), waits the fraction of a second it
//! takes to stop, its memory freed and nothing written, and raises `KeyboardInterrupt`
//! (work that checks no token, reading a scene or checking a mesh, raises at once and
//! finishes in the background).

use halo4d::progress::{Cancel, Event, Job, Observer, Silent};
use halo4d::render::{RenderSettings, Style};
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::create_exception;
use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::mpsc::{RecvTimeoutError, channel};
use std::time::Duration;

create_exception!(
    halo4d,
    SceneError,
    PyValueError,
    "A scene that is not valid: `field` is the path of the field at fault (`surfaces[0].surface.n`, `view.rotation.xw`), or None when the file could not be read; `file` names the scene's source; the message is the command line's."
);

create_exception!(
    halo4d,
    BuildError,
    PyRuntimeError,
    "A build, picture or write that failed: the message is the command line's."
);

/// Work that neither reports nor checks a token (reading a scene, checking a mesh) on a
/// thread of its own, as [`run_job`] runs it, except that Ctrl-C raises at once: the work
/// cannot be stopped, so it finishes in the background and its result is dropped.
fn run<T: Send + 'static>(py: Python<'_>, f: impl FnOnce() -> T + Send + 'static) -> PyResult<T> {
    wait(py, None, move |_| f(), false)
}

/// `f` on a thread of its own with the GIL released, given a job that sends its events to
/// the calling thread when `progress` is given; the calling thread waits in slices of
/// 50 ms, calls `progress` with each event (a dict: `kind` "begin" with `task` and
/// `steps`, "doing" with `text`, "done" with `done`, "end", "warning" and "note" with
/// `text`) and checks for signals. Ctrl-C (or `progress` raising) cancels the work and
/// waits for it to stop (a fraction of a second: its memory is freed, nothing of it is
/// written) before raising.
fn run_job<T: Send + 'static>(
    py: Python<'_>,
    progress: Option<&Bound<'_, PyAny>>,
    f: impl FnOnce(Job) -> T + Send + 'static,
) -> PyResult<T> {
    wait(py, progress, f, true)
}

/// What crosses from the work's thread to the calling one: an event for `progress`, or
/// the result.
enum Message<T> {
    Event(Owned),
    Done(T),
}

/// A [`halo4d::progress::Event`] owned, to send across threads.
struct Owned {
    kind: &'static str,
    task: Option<String>,
    steps: Option<u64>,
    done: Option<u64>,
    text: Option<String>,
}

impl Owned {
    fn of(event: &Event<'_>) -> Owned {
        let mut o = Owned {
            kind: "end",
            task: None,
            steps: None,
            done: None,
            text: None,
        };
        match *event {
            Event::Begin { task, steps } => {
                (o.kind, o.task, o.steps) = ("begin", Some(task.into()), Some(steps));
            }
            Event::Doing(text) => (o.kind, o.text) = ("doing", Some(text.into())),
            Event::Done(done) => (o.kind, o.done) = ("done", Some(done)),
            Event::Warning(text) => (o.kind, o.text) = ("warning", Some(text.into())),
            Event::Note(text) => (o.kind, o.text) = ("note", Some(text.into())),
            _ => {}
        }
        o
    }

    /// The event as `progress` gets it: a dict with `kind` and the event's own keys.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("kind", self.kind)?;
        for (key, value) in [("task", &self.task), ("text", &self.text)] {
            if let Some(v) = value {
                d.set_item(key, v)?;
            }
        }
        for (key, value) in [("steps", self.steps), ("done", self.done)] {
            if let Some(v) = value {
                d.set_item(key, v)?;
            }
        }
        Ok(d)
    }
}

/// [`run_job`] and [`run`]: on Ctrl-C, the work is cancelled and, where it checks its token
/// (`stoppable`), waited for.
fn wait<T: Send + 'static>(
    py: Python<'_>,
    progress: Option<&Bound<'_, PyAny>>,
    f: impl FnOnce(Job) -> T + Send + 'static,
    stoppable: bool,
) -> PyResult<T> {
    let (tx, rx) = channel();
    let cancel = Cancel::new();
    let stop = cancel.clone();
    let report = progress.is_some();
    let worker = std::thread::Builder::new()
        .name("halo4d".into())
        .spawn(move || {
            let events = tx.clone();
            let send = move |e: &Event<'_>| {
                let _ = events.send(Message::Event(Owned::of(e)));
            };
            let observer: &dyn Observer = if report { &send } else { &Silent };
            let value = f(Job::new(observer, &stop));
            let _ = tx.send(Message::Done(value));
        })
        .map_err(|e| PyOSError::new_err(format!("cannot start a thread for halo4d: {e}")))?;
    let mut rx = rx;
    let stopped = |py: Python<'_>, err: PyErr| {
        cancel.cancel();
        // The work stops at its next check; its result (an error) is dropped with it.
        if stoppable {
            let _ = py.detach(|| worker.join());
        }
        Err(err)
    };
    loop {
        let (received, back) = py.detach(move || (rx.recv_timeout(Duration::from_millis(50)), rx));
        rx = back;
        match received {
            Ok(Message::Done(value)) => return Ok(value),
            Ok(Message::Event(event)) => {
                if let Some(progress) = progress
                    && let Err(err) = event.to_dict(py).and_then(|d| progress.call1((d,)))
                {
                    return stopped(py, err);
                }
            }
            Err(RecvTimeoutError::Timeout) => {
                if let Err(err) = py.check_signals() {
                    return stopped(py, err);
                }
            }
            Err(RecvTimeoutError::Disconnected) => {
                return Err(BuildError::new_err(
                    "halo4d's work stopped without a result (a panic: please report it)",
                ));
            }
        }
    }
}

/// A `SceneError` carrying the field and file of `e`.
fn scene_error(py: Python<'_>, e: &halo4d::SceneError) -> PyErr {
    let (field, file) = match e {
        halo4d::SceneError::Io { file, .. } => (None, file.as_str()),
        halo4d::SceneError::Syntax { field, file, .. }
        | halo4d::SceneError::Invalid { field, file, .. } => (Some(field.as_str()), file.as_str()),
    };
    scene_error_at(py, e.to_string(), field, file)
}

/// A `SceneError` saying `message` about `field` (None: the source as a whole) of `file`.
fn scene_error_at(py: Python<'_>, message: String, field: Option<&str>, file: &str) -> PyErr {
    let err = SceneError::new_err(message);
    let value = err.value(py);
    // Setting attributes on a fresh exception instance cannot fail.
    let _ = value.setattr("field", field);
    let _ = value.setattr("file", file);
    err
}

/// A `BuildError` with the message of `e`.
fn build_error(e: impl std::fmt::Display) -> PyErr {
    BuildError::new_err(e.to_string())
}

/// Python's `json.dumps(value)`.
fn dumps(value: &Bound<'_, PyAny>) -> PyResult<String> {
    value
        .py()
        .import("json")?
        .call_method1("dumps", (value,))?
        .extract()
}

/// A serializable value as Python objects (through JSON, as the files have it).
fn to_python<'py>(py: Python<'py>, value: &impl serde::Serialize) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value).map_err(build_error)?;
    py.import("json")?.call_method1("loads", (text,))
}

/// `values` (`width` per row) as an (n, width) array: one copy.
fn matrix<'py, T: numpy::Element + Copy>(
    py: Python<'py>,
    values: &[T],
    width: usize,
) -> PyResult<Bound<'py, PyArray2<T>>> {
    PyArray1::from_slice(py, values).reshape([values.len() / width, width])
}

/// A scene: its surfaces, 4D view, halos, camera, picture and outputs, validated as
/// `halo4d build` validates a scene file.
///
/// `Scene()` is the default scene; `Scene(source)` takes a dict (the scene file's JSON as
/// Python objects), a JSON string, or the path of a scene file (str or os.PathLike; mesh
/// files it names are read relative to its folder). A scene that is not valid raises
/// `SceneError`, whose `field` names the field at fault.
#[pyclass(frozen, module = "halo4d")]
struct Scene {
    scene: Arc<halo4d::Scene>,
    /// The folder mesh files' relative paths start from (the scene file's; else the
    /// working directory).
    folder: PathBuf,
}

impl Scene {
    /// Scene text not from a file: its mesh files' relative paths start from the working
    /// directory, as it is now.
    fn parse(py: Python<'_>, text: &str, file: &str) -> PyResult<Scene> {
        halo4d::Scene::parse(text, file)
            .map(|scene| Scene {
                scene: Arc::new(scene),
                folder: std::env::current_dir().unwrap_or_default(),
            })
            .map_err(|e| scene_error(py, &e))
    }

    /// A scene of the same folder.
    fn sibling(&self, scene: Arc<halo4d::Scene>) -> Scene {
        Scene {
            scene,
            folder: self.folder.clone(),
        }
    }

    /// The scene's JSON with every mesh file's path taken from its folder, so that the JSON
    /// reads back anywhere.
    fn json(&self) -> PyResult<serde_json::Value> {
        let mut json = serde_json::to_value(&*self.scene).map_err(build_error)?;
        if let Some(surfaces) = json.get_mut("surfaces").and_then(|s| s.as_array_mut()) {
            for entry in surfaces {
                let surface = &mut entry["surface"];
                if surface["type"] == "mesh"
                    && let Some(path) = surface["path"].as_str()
                    && std::path::Path::new(path).is_relative()
                {
                    let full = std::path::absolute(self.folder.join(path))
                        .map_err(|e| PyOSError::new_err(e.to_string()))?;
                    surface["path"] = full.display().to_string().into();
                }
            }
        }
        Ok(json)
    }

    /// This scene in the 4D `view` (a dict as a scene file's `view`), validated; its
    /// surfaces kept, not read again.
    fn in_view(
        &self,
        py: Python<'_>,
        view: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Arc<halo4d::Scene>> {
        let Some(view) = view.filter(|v| !v.is_none()) else {
            return Ok(Arc::clone(&self.scene));
        };
        let file = format!("<{} with a view>", self.scene.name);
        self.scene
            .with_view(&dumps(view)?, &file)
            .map(Arc::new)
            .map_err(|e| scene_error(py, &e))
    }
}

#[pymethods]
impl Scene {
    #[new]
    #[pyo3(signature = (source = None))]
    fn new(py: Python<'_>, source: Option<&Bound<'_, PyAny>>) -> PyResult<Scene> {
        let Some(source) = source.filter(|s| !s.is_none()) else {
            return Ok(Scene {
                scene: Arc::new(halo4d::Scene::default_scene()),
                folder: PathBuf::new(),
            });
        };
        if source.is_instance_of::<PyDict>() {
            return Scene::parse(py, &dumps(source)?, "<dict>");
        }
        if let Ok(text) = source.downcast::<PyString>() {
            let text = text.to_cow()?;
            if text.trim_start().starts_with('{') {
                return Scene::parse(py, &text, "<json>");
            }
        }
        let path: PathBuf = source.extract().map_err(|_| {
            scene_error_at(
                py,
                format!(
                    "a scene is a dict, a JSON string or the path of a scene file, not {}",
                    source
                        .get_type()
                        .name()
                        .map_or_else(|_| "this".into(), |n| n.to_string())
                ),
                None,
                "<argument>",
            )
        })?;
        let folder = path.parent().map(PathBuf::from).unwrap_or_default();
        let scene = run(py, move || halo4d::Scene::load(&path))?;
        scene
            .map(|scene| Scene {
                scene: Arc::new(scene),
                folder,
            })
            .map_err(|e| scene_error(py, &e))
    }

    /// The scene's name (its outputs' folder and file names).
    #[getter]
    fn name(&self) -> String {
        self.scene.name.clone()
    }

    /// The scene as the JSON of a scene file (mesh files' paths absolute, so that it
    /// reads back from anywhere).
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string_pretty(&self.json()?).map_err(build_error)
    }

    /// The scene as a dict (the JSON of a scene file, as Python objects; mesh files' paths
    /// absolute).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.json()?)
    }

    /// Samples the scene's surfaces in 4D (adaptively, as its `sampling` says), once: the
    /// result builds any number of 4D views without sampling again. `progress` is called
    /// with each of the work's events (`halo4d.tqdm_progress()` draws them as bars).
    #[pyo3(signature = (progress = None))]
    fn sample(&self, py: Python<'_>, progress: Option<&Bound<'_, PyAny>>) -> PyResult<Sampled> {
        let scene = Arc::clone(&self.scene);
        let sampled = run_job(py, progress, move |job| {
            halo4d::Sampled::sample(&scene, job)
        })?
        .map_err(build_error)?;
        Ok(Sampled {
            scene: self.sibling(Arc::clone(&self.scene)),
            sampled: Arc::new(sampled),
        })
    }

    /// Samples and builds the scene (in the 4D `view`, a dict as a scene file's `view`,
    /// else the scene's): surfaces, halos, curves and their verification, as `halo4d
    /// build` makes them, nothing written. `progress` as `sample` takes it.
    #[pyo3(signature = (view = None, progress = None))]
    fn build(
        &self,
        py: Python<'_>,
        view: Option<&Bound<'_, PyAny>>,
        progress: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Built> {
        self.sample(py, progress)?.build(py, view, None, progress)
    }

    fn __repr__(&self) -> String {
        format!(
            "halo4d.Scene({:?}: {} surface(s))",
            self.scene.name,
            self.scene.surfaces.len()
        )
    }
}

/// A scene's surfaces sampled in 4D (`Scene.sample()`), to build in any number of views.
#[pyclass(frozen, module = "halo4d")]
struct Sampled {
    scene: Scene,
    sampled: Arc<halo4d::Sampled>,
}

#[pymethods]
impl Sampled {
    /// Builds the sampled surfaces in the 4D `view` (a dict as a scene file's `view`, else
    /// the scene's; a scene's `"view": "auto"` is searched first, as `halo4d build` does):
    /// projected surfaces, halos, curves and their verification. `scene` builds another
    /// scene with the same surfaces and sampling (another halo, camera, picture or
    /// outputs) without sampling again; one with other surfaces or sampling is refused.
    /// `progress` as `Scene.sample` takes it.
    #[pyo3(signature = (view = None, scene = None, progress = None))]
    fn build(
        &self,
        py: Python<'_>,
        view: Option<&Bound<'_, PyAny>>,
        scene: Option<PyRef<'_, Scene>>,
        progress: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Built> {
        let base = match &scene {
            None => &self.scene,
            Some(other) => {
                let (mine, theirs) = (&self.scene.scene, &other.scene);
                if theirs.surfaces != mine.surfaces || theirs.sampling != mine.sampling {
                    return Err(PyValueError::new_err(format!(
                        "scene `{}` has other surfaces or sampling than `{}`, which was sampled: sample it (`scene.sample()`)",
                        theirs.name, mine.name
                    )));
                }
                &**other
            }
        };
        let scene = base.in_view(py, view)?;
        let sampled = Arc::clone(&self.sampled);
        let (scene, built) = run_job(py, progress, move |job| {
            let mut scene = (*scene).clone();
            halo4d::resolve_view(&mut scene, job).map_err(build_error)?;
            let built = (*sampled)
                .clone()
                .into_built_with(&scene, halo4d::Stages::of(&scene), job)
                .map_err(build_error)?;
            Ok::<_, PyErr>((scene, built))
        })??;
        Ok(Built {
            scene: base.sibling(Arc::new(scene)),
            built: Arc::new(built),
        })
    }

    /// Triangles of all the surfaces.
    #[getter]
    fn triangles(&self) -> usize {
        self.sampled.triangles()
    }

    fn __repr__(&self) -> String {
        format!(
            "halo4d.Sampled({:?}: {} triangles)",
            self.scene.scene.name,
            self.sampled.triangles()
        )
    }
}

/// A scene built in one 4D view: its surfaces, halos and curves as arrays, the verdict,
/// the report; it writes the files and renders the picture.
#[pyclass(frozen, module = "halo4d")]
struct Built {
    scene: Scene,
    built: Arc<halo4d::Built>,
}

#[pymethods]
impl Built {
    /// The scene it was built from, in the view it was built in.
    #[getter]
    fn scene(&self) -> Scene {
        self.scene.sibling(Arc::clone(&self.scene.scene))
    }

    /// Whether the build is verified: every halo passes the checker, every curve is
    /// resolved, and the halos' verification against the curves found nothing wrong.
    #[getter]
    fn verified(&self) -> bool {
        self.built.failures().is_empty()
    }

    /// What keeps the build from being verified (empty when it is).
    #[getter]
    fn failures(&self) -> Vec<String> {
        self.built.failures()
    }

    /// Each surface: its 4D mesh, its projection and its halo.
    #[getter]
    fn surfaces(&self) -> Vec<Surface> {
        (0..self.built.surfaces.len())
            .map(|index| Surface {
                built: Arc::clone(&self.built),
                index,
            })
            .collect()
    }

    /// The self-intersection curves the files and the picture show (refined onto the
    /// surfaces where the scene's `curves.refine` says).
    #[getter]
    fn curves(&self) -> Vec<Curve> {
        (0..self.built.shown_curves().curves.len())
            .map(|index| Curve {
                built: Arc::clone(&self.built),
                index,
            })
            .collect()
    }

    /// Where three sheets cross: an (n, 3) array of positions.
    #[getter]
    fn triple_points<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let points: Vec<f64> = self
            .built
            .shown_curves()
            .triple_points
            .iter()
            .flat_map(|t| t.position.to_array())
            .collect();
        matrix(py, &points, 3)
    }

    /// The build's report as a dict: what `report.json` holds, without the files (nothing
    /// was written) and the picture (none was made).
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &halo4d::report_of(&self.scene.scene, &self.built))
    }

    /// Writes the files the scene's `outputs` ask for into `dir` (created if need be; every
    /// file written whole or not at all), and gives the report (`report.json`) as a dict.
    /// `progress` as `Scene.sample` takes it.
    #[pyo3(signature = (dir, progress = None))]
    fn write<'py>(
        &self,
        py: Python<'py>,
        dir: PathBuf,
        progress: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (scene, built) = (Arc::clone(&self.scene.scene), Arc::clone(&self.built));
        let report = run_job(py, progress, move |job| {
            halo4d::write_with(&scene, &built, &dir, job)
        })?
        .map_err(build_error)?;
        to_python(py, &report)
    }

    /// The picture, as `halo4d render` makes it with the scene's `render` and `camera`
    /// (width, height, samples per pixel and style `"shaded"` or `"stipple"` override
    /// them): an (height, width, 3) array of uint8 sRGB. The halos are the build's: a
    /// scene whose `halo.gap_px` sets their gap in pixels of its own picture shows that gap
    /// at its own size, and scaled with the picture at another.
    #[pyo3(signature = (width = None, height = None, style = None, samples = None))]
    fn render<'py>(
        &self,
        py: Python<'py>,
        width: Option<u32>,
        height: Option<u32>,
        style: Option<&str>,
        samples: Option<u32>,
    ) -> PyResult<Bound<'py, numpy::PyArray3<u8>>> {
        let base = self.scene.scene.render;
        let style = match style {
            None => base.style,
            Some("shaded") => Style::Shaded,
            Some("stipple") => Style::Stipple,
            Some(other) => {
                return Err(PyValueError::new_err(format!(
                    "style `{other}`: use \"shaded\" or \"stipple\""
                )));
            }
        };
        let settings = RenderSettings {
            width: width.unwrap_or(base.width),
            height: height.unwrap_or(base.height),
            samples: samples.unwrap_or(base.samples),
            style,
            ..base
        };
        settings
            .check()
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        if style == Style::Stipple && !self.built.stages.stipples {
            return Err(PyValueError::new_err(
                "style \"stipple\": this scene was built without stipples; set its render.style to \"stipple\" and build again",
            ));
        }
        let (scene, built) = (Arc::clone(&self.scene.scene), Arc::clone(&self.built));
        let picture = run_job(py, None, move |job| {
            let parts = built.parts(&scene.halo);
            halo4d::render::render_until(&parts, &settings, &scene.camera, job.cancel())
        })?
        .map_err(build_error)?;
        PyArray1::from_slice(py, &picture.rgb).reshape([
            picture.height as usize,
            picture.width as usize,
            3,
        ])
    }

    /// The scene's `.glb` (surfaces, halos, curves, the 4D mesh and the scene), as bytes.
    fn glb<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyBytes>> {
        let (scene, built) = (Arc::clone(&self.scene.scene), Arc::clone(&self.built));
        let bytes = run(py, move || halo4d::glb_bytes(&scene, &built))?.map_err(build_error)?;
        Ok(pyo3::types::PyBytes::new(py, &bytes))
    }

    fn __repr__(&self) -> String {
        format!(
            "halo4d.Built({:?}: {} surface(s), {} curve(s), {})",
            self.scene.scene.name,
            self.built.surfaces.len(),
            self.built.shown_curves().curves.len(),
            if self.verified() {
                "verified"
            } else {
                "NOT verified"
            }
        )
    }
}

/// One surface of a build.
#[pyclass(frozen, module = "halo4d")]
struct Surface {
    built: Arc<halo4d::Built>,
    index: usize,
}

impl Surface {
    fn product(&self) -> &halo4d::SurfaceProduct {
        &self.built.surfaces[self.index]
    }
}

#[pymethods]
impl Surface {
    /// The surface's name.
    #[getter]
    fn name(&self) -> String {
        self.product().name.clone()
    }

    /// The 4D mesh's vertices, (n, 4), in the surface's own coordinates.
    #[getter]
    fn vertices4d<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        matrix(py, bytemuck::cast_slice(&self.product().mesh.positions), 4)
    }

    /// The projected vertices, (n, 3): turned, moved and projected by the view, rounded to
    /// f32 as the files store them (the `.ply`'s frame).
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        matrix(
            py,
            bytemuck::cast_slice(&self.product().projected.positions),
            3,
        )
    }

    /// Each vertex's w after the view's turn (its depth in 4D; smaller is nearer), (n,).
    #[getter]
    fn w<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.product().projected.w)
    }

    /// The projected surface's unit vertex normals, (n, 3).
    #[getter]
    fn normals<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        matrix(
            py,
            bytemuck::cast_slice(&self.product().projected.normals),
            3,
        )
    }

    /// The triangles, (m, 3) vertex indices, wound as the files wind them.
    #[getter]
    fn triangles<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<u32>>> {
        matrix(py, bytemuck::cast_slice(&self.product().mesh.triangles), 3)
    }

    /// The surface's halo, or None where it has none.
    #[getter]
    fn halo(&self) -> Option<Halo> {
        (!self.product().halo.tets.is_empty()).then(|| Halo {
            built: Arc::clone(&self.built),
            index: self.index,
        })
    }

    fn __repr__(&self) -> String {
        let p = self.product();
        format!(
            "halo4d.Surface({:?}: {} vertices, {} triangles)",
            p.name,
            p.mesh.positions.len(),
            p.mesh.triangles.len()
        )
    }
}

/// A surface's volumetric halo: conforming tetrahedra around the projected surface.
#[pyclass(frozen, module = "halo4d")]
struct Halo {
    built: Arc<halo4d::Built>,
    index: usize,
}

impl Halo {
    fn halo(&self) -> &halo4d::halo::Halo {
        &self.built.surfaces[self.index].halo
    }
}

#[pymethods]
impl Halo {
    /// Its vertices, (k, 3): the offsets below and above the surface, the surface's own
    /// vertices, then any inserted ones (the `.vtk`'s POINTS).
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        matrix(py, bytemuck::cast_slice(&self.halo().positions), 3)
    }

    /// Its tetrahedra, (t, 4) vertex indices, in the files' order (the `.vtk`'s and
    /// meshio's: seen from the fourth vertex the first three run counter-clockwise,
    /// det[b - a, c - a, d - a] > 0).
    #[getter]
    fn tetrahedra<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<u32>>> {
        let tets: Vec<u32> = self
            .halo()
            .tets
            .iter()
            .flat_map(|&t| halo4d::internals::file_order(t))
            .collect();
        matrix(py, &tets, 4)
    }

    /// Each vertex's t, (k,): 0 on the negative offset, 1 on the positive, 0.5 on the
    /// surface (an inserted vertex has the mean of its layer's corners).
    #[getter]
    fn t<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.halo().t)
    }

    /// Each vertex's d_orig, the w of the surface point it was offset from, (k,).
    #[getter]
    fn d_orig<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.halo().d_orig)
    }

    /// How many of the vertices are the surface's own.
    #[getter]
    fn surface_vertices(&self) -> usize {
        self.halo().surface_vertices
    }

    fn __repr__(&self) -> String {
        format!(
            "halo4d.Halo({} vertices, {} tetrahedra)",
            self.halo().positions.len(),
            self.halo().tets.len()
        )
    }
}

/// A self-intersection curve of the projected surfaces, with the two sheets that cross
/// along it.
#[pyclass(frozen, module = "halo4d")]
struct Curve {
    built: Arc<halo4d::Built>,
    index: usize,
}

impl Curve {
    fn curve(&self) -> &halo4d::intersect::Curve {
        &self.built.shown_curves().curves[self.index]
    }
}

#[pymethods]
impl Curve {
    /// Its points, (p, 3), in order.
    #[getter]
    fn points<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let p: Vec<f64> = self
            .curve()
            .points
            .iter()
            .flat_map(|p| p.position.to_array())
            .collect();
        matrix(py, &p, 3)
    }

    /// The w of its two sheets at each point, (p, 2), labelled consistently along it.
    #[getter]
    fn w<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let w: Vec<f64> = self.curve().points.iter().flat_map(|p| p.w).collect();
        matrix(py, &w, 2)
    }

    /// The surface (index into `Built.surfaces`) of each of its two sheets at each point,
    /// (p, 2).
    #[getter]
    fn sheets<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<u32>>> {
        let s: Vec<u32> = self
            .curve()
            .points
            .iter()
            .flat_map(|p| p.faces.map(|f| f.surface))
            .collect();
        matrix(py, &s, 2)
    }

    /// Which sheet (0 or 1) passes over the other at each point (nearer in w), (p,).
    #[getter]
    fn over<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u8>> {
        let over: Vec<u8> = self.curve().points.iter().map(|p| p.near() as u8).collect();
        PyArray1::from_slice(py, &over)
    }

    /// Whether it closes on itself.
    #[getter]
    fn closed(&self) -> bool {
        self.curve().closed
    }

    /// How its two ends end: "closed", "boundary", "branch_point" (a cross-cap or a
    /// singular point of the projection) or "branch" (unresolved).
    #[getter]
    fn ends(&self) -> [&'static str; 2] {
        self.curve().ends.map(|e| match e {
            halo4d::intersect::End::Closed => "closed",
            halo4d::intersect::End::Boundary => "boundary",
            halo4d::intersect::End::BranchPoint => "branch_point",
            halo4d::intersect::End::Branch => "branch",
        })
    }

    fn __len__(&self) -> usize {
        self.curve().points.len()
    }

    fn __repr__(&self) -> String {
        format!(
            "halo4d.Curve({} points, {})",
            self.curve().points.len(),
            if self.curve().closed {
                "closed"
            } else {
                "open"
            }
        )
    }
}

/// The catalogue of surfaces: per entry its `type` (as a scene file names it), a
/// description, and its topology (`closed`, `orientable`, `euler_characteristic`).
#[pyfunction]
fn catalogue<'py>(py: Python<'py>) -> PyResult<Vec<Bound<'py, PyAny>>> {
    halo4d::surfaces::Surface::catalogue()
        .iter()
        .map(|s| {
            let t = s.topology();
            let entry = PyDict::new(py);
            entry.set_item("type", s.type_name())?;
            entry.set_item("description", s.description())?;
            entry.set_item("closed", t.closed)?;
            entry.set_item("orientable", t.orientable)?;
            entry.set_item("euler_characteristic", t.euler_characteristic)?;
            Ok(entry.into_any())
        })
        .collect()
}

/// `halo4d check` on a file (a `.glb` or `.vtk`) or a build's folder: a dict with
/// `verified`, `failures`, `halos` (each halo's name and the checker's statistics), for a
/// folder the `curves` recomputed from its surfaces and the halos' `verification` against
/// them, the `scene` the file records, `plain` (why a mesh is not read as a halo, or None),
/// for another program's tetrahedral mesh (`.vtk`, `.vtu`, `.msh`, `.mesh`, `.node`/`.ele`)
/// its `certificate` (`convention`, `boundary`, `quality`, for a mixed mesh `cells`, and
/// `faults`: each cell's fault bits, its tetrahedra first, then its hexahedra, wedges and
/// pyramids in the file's order) and `format`, and `text` (what the command prints). A file that cannot be
/// read raises `OSError`.
#[pyfunction]
fn check<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyAny>> {
    let target = path.clone();
    let checked = run(py, move || {
        if target.is_dir() {
            halo4d::check_dir(&target)
        } else {
            halo4d::check_file(&target)
        }
    })?
    .map_err(|e| PyOSError::new_err(e.to_string()))?;
    checked_dict(py, &checked)
}

/// The certificate of cells given as arrays (what `halo4d.check` makes of a PyVista grid, a
/// meshio mesh or `(points, cells)`): `points` (n, 3) float64, `tets` (m, 4) int64 in VTK's
/// convention (a, b, c, d positive when det[b - a, c - a, d - a] > 0), `solids` (k, 10)
/// int64, a hexahedron's, wedge's or pyramid's VTK type (12, 13, 14), its number and its
/// corners in VTK's order (padded with 0), `name` and `format` saying where they came from.
/// The dict of `check`; indices out of range, unknown types or non-finite points raise
/// `ValueError`.
#[pyfunction]
fn certify_arrays<'py>(
    py: Python<'py>,
    points: numpy::PyReadonlyArray2<'py, f64>,
    tets: numpy::PyReadonlyArray2<'py, i64>,
    solids: numpy::PyReadonlyArray2<'py, i64>,
    name: String,
    format: String,
) -> PyResult<Bound<'py, PyAny>> {
    let (p, t, s) = (points.as_array(), tets.as_array(), solids.as_array());
    if p.ncols() != 3 || t.ncols() != 4 || s.ncols() != 10 {
        return Err(PyValueError::new_err(format!(
            "points must be (n, 3), tetrahedra (m, 4) and other cells (k, 10); got {:?}, {:?} and {:?}",
            p.shape(),
            t.shape(),
            s.shape()
        )));
    }
    let positions: Vec<[f64; 3]> = p.rows().into_iter().map(|r| [r[0], r[1], r[2]]).collect();
    let n = positions.len();
    let mut cells = Vec::with_capacity(t.nrows());
    for (k, r) in t.rows().into_iter().enumerate() {
        let mut c = [0u32; 4];
        for (slot, &i) in c.iter_mut().zip(r.iter()) {
            *slot = u32::try_from(i)
                .ok()
                .filter(|&i| (i as usize) < n)
                .ok_or_else(|| {
                    PyValueError::new_err(format!(
                        "tetrahedron {k} names point {i}, but there are {n} points"
                    ))
                })?;
        }
        cells.push(c);
    }
    use halo4d::import::{Solid, SolidKind};
    let mut others = Vec::with_capacity(s.nrows());
    for r in s.rows() {
        let kind = match r[0] {
            12 => SolidKind::Hexahedron,
            13 => SolidKind::Wedge,
            14 => SolidKind::Pyramid,
            t => {
                return Err(PyValueError::new_err(format!(
                    "cell {} has VTK type {t}, not 12, 13 or 14 (a hexahedron, wedge or pyramid)",
                    r[1]
                )));
            }
        };
        let mut corners = [0u32; 8];
        for (slot, &i) in corners.iter_mut().zip(r.iter().skip(2)) {
            *slot = u32::try_from(i).map_err(|_| {
                PyValueError::new_err(format!("cell {} names point {i}, which is no point", r[1]))
            })?;
        }
        let id = u64::try_from(r[1]).unwrap_or(0);
        others.push(Solid { kind, corners, id });
    }
    let mesh = halo4d::import::PlainTetrahedra::from_arrays(&name, &format, positions, &cells)
        .and_then(|m| m.with_solids(others))
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    let label = PathBuf::from(&name);
    let checked = run(py, move || halo4d::check_mesh(&label, mesh))?;
    checked_dict(py, &checked)
}

/// What `check` gives for a `Checked`.
fn checked_dict<'py>(py: Python<'py>, checked: &halo4d::Checked) -> PyResult<Bound<'py, PyAny>> {
    let out = PyDict::new(py);
    let failures = checked.failures();
    out.set_item("verified", failures.is_empty())?;
    out.set_item("failures", failures)?;
    let halos = checked
        .halos
        .iter()
        .map(|(name, stats)| {
            let entry = to_python(py, stats)?;
            entry.set_item("name", name)?;
            Ok(entry)
        })
        .collect::<PyResult<Vec<_>>>()?;
    out.set_item("halos", halos)?;
    if let Some((curves, verification)) = &checked.verification {
        out.set_item("curves", to_python(py, curves)?)?;
        out.set_item("verification", to_python(py, verification)?)?;
    }
    out.set_item("scene", checked.scene.clone())?;
    out.set_item("plain", checked.plain.clone())?;
    if let Some(certificate) = &checked.certificate {
        let entry = to_python(py, certificate)?;
        entry.set_item(
            "faults",
            PyArray1::from_slice(py, certificate.cell_faults()),
        )?;
        out.set_item("certificate", entry)?;
    }
    out.set_item("format", checked.mesh.as_ref().map(|m| m.format.clone()))?;
    out.set_item("text", checked.text())?;
    Ok(out.into_any())
}

/// halo4d's native module; `halo4d` re-exports it.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("SceneError", py.get_type::<SceneError>())?;
    m.add("BuildError", py.get_type::<BuildError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<Scene>()?;
    m.add_class::<Sampled>()?;
    m.add_class::<Built>()?;
    m.add_class::<Surface>()?;
    m.add_class::<Halo>()?;
    m.add_class::<Curve>()?;
    m.add_function(wrap_pyfunction!(catalogue, m)?)?;
    m.add_function(wrap_pyfunction!(check, m)?)?;
    m.add_function(wrap_pyfunction!(certify_arrays, m)?)?;
    Ok(())
}
