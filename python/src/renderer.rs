//! `twister.Renderer` (one device and its pipelines, open as long as the object lives) and
//! `twister.Scene` (a file loaded once and reused by renders).

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};

use pyo3::prelude::*;
use pyo3::types::PyDict;
use twister::error::Error;
use twister_cli::scene::prepare_loaded;

use crate::frame::Frame;
use crate::options::{parse, ErrorCmd, RenderCmd, SpeedCmd};
use crate::without_gil;

/// Two arrays, the left eye's and the right eye's.
type EyeArrays = (Py<PyAny>, Py<PyAny>);

/// Adapters opened by this process (every `Renderer()` opens one).
static ADAPTERS_OPENED: AtomicU64 = AtomicU64::new(0);

/// A scene file loaded once: renders given it place a copy (`fit`, `scale`, `viewer` apply per
/// render) instead of reading the file again.
#[pyclass(module = "twister._twister", name = "Scene", frozen)]
pub struct Scene {
    #[pyo3(get)]
    spec: String,
    /// The placement options given to `load`, put before each render's own.
    #[pyo3(get)]
    placement: Vec<String>,
    loaded: Option<Arc<twister::Scene>>,
}

#[pymethods]
impl Scene {
    /// Triangles in the scene as loaded (None for a built-in scene, made per render).
    #[getter]
    fn triangles(&self) -> Option<usize> {
        self.loaded.as_ref().map(|s| s.triangle_count())
    }

    fn __repr__(&self) -> String {
        format!("<twister.Scene {:?}>", self.spec)
    }
}

struct State {
    renderer: twister::Renderer,
    renders: u64,
    scenes_loaded: u64,
}

/// One GPU device and its pipelines, kept open: every render, measurement and benchmark on it
/// reuses them. Threads may share it; their calls take turns.
#[pyclass(module = "twister._twister", name = "Renderer", frozen)]
pub struct Renderer {
    state: Mutex<State>,
    #[pyo3(get)]
    adapter: String,
}

impl Renderer {
    fn lock(&self) -> MutexGuard<'_, State> {
        // A panic is caught and reported where it happened; the renderer stays usable.
        self.state.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
    }
}

/// The options with a loaded scene's in front: its spec first, then its placement.
fn with_scene(argv: Vec<String>, scene: Option<&Scene>) -> Vec<String> {
    match scene {
        Some(s) => std::iter::once(s.spec.clone()).chain(s.placement.iter().cloned()).chain(argv).collect(),
        None => argv,
    }
}

#[pymethods]
impl Renderer {
    #[new]
    #[pyo3(signature = (adapter=None))]
    fn new(py: Python<'_>, adapter: Option<String>) -> PyResult<Self> {
        let (renderer, description) = without_gil(py, move || {
            let gpu = twister::gpu::Gpu::with_adapter(adapter.as_deref())?;
            let description = gpu.adapter_description();
            Ok((twister::Renderer::new(gpu)?, description))
        })?;
        ADAPTERS_OPENED.fetch_add(1, Ordering::Relaxed);
        Ok(Renderer { state: Mutex::new(State { renderer, renders: 0, scenes_loaded: 0 }), adapter: description })
    }

    /// Counters: `renders` (frames drawn by this renderer), `scenes_loaded` (files read by
    /// `load`) and `adapters_opened` (by this process).
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let (renders, scenes_loaded) = py.detach(|| {
            let state = self.lock();
            (state.renders, state.scenes_loaded)
        });
        let d = PyDict::new(py);
        d.set_item("renders", renders)?;
        d.set_item("scenes_loaded", scenes_loaded)?;
        d.set_item("adapters_opened", ADAPTERS_OPENED.load(Ordering::Relaxed))?;
        Ok(d)
    }

    /// Loads `spec` once (a file; a built-in scene is made per render), its placement options
    /// checked now and applied at each render.
    fn _load(&self, py: Python<'_>, spec: String, placement: Vec<String>) -> PyResult<Scene> {
        let argv: Vec<String> = std::iter::once(spec.clone()).chain(placement.iter().cloned()).collect();
        let args = parse::<RenderCmd>(&argv)?.args;
        if spec.starts_with("builtin:") {
            args.view.settings(&[args.view.method]).map_err(crate::to_py)?;
            return Ok(Scene { spec, placement, loaded: None });
        }
        let loaded = without_gil(py, || {
            let loaded = twister::core::scenes::load::load_scene(&spec, &twister::Projection::default())?;
            self.lock().scenes_loaded += 1;
            Ok(loaded)
        })?;
        Ok(Scene { spec, placement, loaded: Some(Arc::new(loaded)) })
    }

    /// Draws a still (each CAVE wall, or the one panorama) as `twister render` draws it.
    #[pyo3(signature = (argv, scene=None))]
    fn _render(&self, py: Python<'_>, argv: Vec<String>, scene: Option<PyRef<'_, Scene>>) -> PyResult<Vec<Frame>> {
        let argv = with_scene(argv, scene.as_deref());
        let args = parse::<RenderCmd>(&argv)?.args;
        if args.frames.is_some() {
            return Err(crate::TwisterError::new_err("frames: a sequence is drawn by render_frames"));
        }
        let loaded = scene.as_ref().and_then(|s| s.loaded.clone());
        let adapter = self.adapter.clone();
        let drawn = without_gil(py, || {
            // The lock is taken without the GIL: a thread waiting for it never blocks the one
            // that holds it from coming back to Python.
            let mut state = self.lock();
            let still = twister_cli::render::still(&args)?;
            let method = [still.settings.subdivision.method];
            let r = &state.renderer;
            let prepared = prepare_loaded(
                r,
                &args.scene,
                loaded.as_deref(),
                args.fit,
                &args.view,
                still.settings,
                args.lod_overlay,
                &method,
            )?;
            let views = still.placed(prepared.settings);
            let all: Vec<twister::RenderSettings> = views.iter().map(|(s, _)| *s).collect();
            if twister_cli::tiled::any_tiled(r, &all, args.max_tile) {
                return Err(beyond_the_adapter());
            }
            let drawn = twister_cli::render::draw(r, &adapter, &args, &prepared, views, true)?;
            state.renders += drawn.len() as u64;
            Ok(drawn)
        })?;
        drawn
            .into_iter()
            .map(|d| {
                let wall = d.writer.wall().map(str::to_string);
                let stats = d.record.unwrap_or_default();
                Frame::new(py, d.frame, d.settings, argv.clone(), wall, stats, None)
            })
            .collect()
    }

    /// Draws frame `frame` of a sequence (`frames`, `fps`, animation, paths) as `twister render
    /// --frames` draws it.
    #[pyo3(signature = (argv, frame, scene=None))]
    fn _render_frame(
        &self,
        py: Python<'_>,
        argv: Vec<String>,
        frame: u32,
        scene: Option<PyRef<'_, Scene>>,
    ) -> PyResult<Vec<Frame>> {
        let mut argv = with_scene(argv, scene.as_deref());
        argv.extend(["--frames".to_string(), format!("{frame}..{frame}")]);
        let args = parse::<RenderCmd>(&argv)?.args;
        let loaded = scene.as_ref().and_then(|s| s.loaded.clone());
        let adapter = self.adapter.clone();
        let drawn = without_gil(py, || {
            let mut state = self.lock();
            let checked = twister_cli::sequence::check_sequence(&args)?;
            let mut opened = twister_cli::sequence::open_sequence(&args, checked, &state.renderer, loaded.as_deref())?;
            if opened.any_tiled() {
                return Err(beyond_the_adapter());
            }
            let views = opened.draw(frame)?;
            let writers = opened.writers.clone();
            drop(opened);
            state.renders += views.len() as u64;
            Ok(views.into_iter().zip(writers).map(|(v, w)| (v, w, adapter.clone())).collect::<Vec<_>>())
        })?;
        let scene_name = args.scene.clone();
        drawn
            .into_iter()
            .map(|((settings, rendered), writer, adapter)| {
                let record = twister_cli::writer::FrameRecord::new(
                    &scene_name,
                    &settings,
                    &rendered,
                    &writer,
                    &adapter,
                    serde_json::Value::Null,
                );
                let mut stats = serde_json::to_value(&record).unwrap_or_default();
                stats["frame"] = frame.into();
                let wall = writer.wall().map(str::to_string);
                Frame::new(py, rendered, settings, argv.clone(), wall, stats, Some(frame))
            })
            .collect()
    }

    /// Measures the display-position error as `twister error --json` does: each view's JSON
    /// text and, with `heatmap`, each eye's per-pixel error.
    #[pyo3(signature = (argv, scene=None, heatmap=false))]
    fn _error(
        &self,
        py: Python<'_>,
        argv: Vec<String>,
        scene: Option<PyRef<'_, Scene>>,
        heatmap: bool,
    ) -> PyResult<Vec<(String, Option<EyeArrays>)>> {
        let argv = with_scene(argv, scene.as_deref());
        let args = parse::<ErrorCmd>(&argv)?.args;
        let loaded = scene.as_ref().and_then(|s| s.loaded.clone());
        let adapter = self.adapter.clone();
        let measured = without_gil(py, || {
            let mut state = self.lock();
            let plan = twister_cli::measure::plan_measure(&args)?;
            let measured =
                twister_cli::measure::measure_views(&state.renderer, &adapter, &args, plan, loaded.as_deref())?;
            state.renders += measured.len() as u64;
            Ok(measured)
        })?;
        measured
            .into_iter()
            .map(|m| {
                let p = m.settings.projection();
                let shape = [p.height as usize, p.width as usize];
                let [l, r] = m.error;
                let maps = if heatmap {
                    let array = |v: Vec<f32>| -> PyResult<Py<PyAny>> {
                        use numpy::PyArrayMethods;
                        Ok(numpy::PyArray1::from_vec(py, v).reshape(shape)?.into_any().unbind())
                    };
                    Some((array(l)?, array(r)?))
                } else {
                    None
                };
                Ok((m.json.to_string(), maps))
            })
            .collect()
    }

    /// `twister bench speed --json`'s rows, as JSON text.
    fn _bench_speed(&self, py: Python<'_>, argv: Vec<String>) -> PyResult<String> {
        let args = parse::<SpeedCmd>(&argv)?.args;
        let rows = without_gil(py, || {
            let mut state = self.lock();
            state.renders += 1;
            twister_cli::bench::speed_rows(&state.renderer, &args, |_| {})
        })?;
        Ok(serde_json::to_string(&rows).unwrap_or_default())
    }

    fn __repr__(&self) -> String {
        format!("<twister.Renderer on {}>", self.adapter)
    }
}

/// A frame larger than the adapter draws at once: the command line draws it in tiles, streamed
/// to files; the package keeps frames in memory.
fn beyond_the_adapter() -> Error {
    Error::option(
        "--width",
        "the frame is larger than this adapter draws at once: render it with the command line (twister render), which draws it in tiles",
    )
}
