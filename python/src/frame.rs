//! `twister.Frame`: a rendered frame's pixels as numpy arrays (made from the read-back without
//! copying), its statistics, and `save`, which writes the files `twister render` writes.

use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyAny;
use twister::{EyeImage, FrameStats};

use crate::options::{parse, RenderCmd};
use crate::without_gil;

/// One eye pair, drawn: `left` and `right` (H, W, 4) uint8; `depth` (left, right) (H, W)
/// float32 metres (inf: background) with `depth=True`; `hdr` (left, right) (H, W, 3) float32
/// linear colour with `hdr=True`; `stats` the fields `--stats` writes; `wall` the CAVE wall.
#[pyclass(module = "twister._twister", name = "Frame", frozen)]
pub struct Frame {
    #[pyo3(get)]
    left: Py<PyAny>,
    #[pyo3(get)]
    right: Py<PyAny>,
    #[pyo3(get)]
    depth: Option<(Py<PyAny>, Py<PyAny>)>,
    #[pyo3(get)]
    hdr: Option<(Py<PyAny>, Py<PyAny>)>,
    #[pyo3(get)]
    wall: Option<String>,
    #[pyo3(get)]
    width: u32,
    #[pyo3(get)]
    height: u32,
    stats_json: String,
    frame_stats: FrameStats,
    /// The options it was drawn with (`save` writes what `render` writes with them).
    argv: Vec<String>,
    /// The settings it was drawn with, placed with the scene.
    settings: twister::RenderSettings,
    /// A sequence's frame number (`render_frames`): its files are named as `--frames` names them.
    #[pyo3(get)]
    frame: Option<u32>,
}

/// A flat vector as a numpy array of `shape`, without copying.
fn array<'py, T: numpy::Element>(py: Python<'py>, data: Vec<T>, shape: &[usize]) -> PyResult<Py<PyAny>> {
    Ok(PyArray1::from_vec(py, data).reshape(shape)?.into_any().unbind())
}

impl Frame {
    /// Moves a drawn frame's buffers into numpy arrays.
    pub fn new(
        py: Python<'_>,
        frame: twister::Frame,
        settings: twister::RenderSettings,
        argv: Vec<String>,
        wall: Option<String>,
        stats: serde_json::Value,
        number: Option<u32>,
    ) -> PyResult<Frame> {
        let (w, h) = (frame.left.width as usize, frame.left.height as usize);
        let pair = |[l, r]: [Vec<f32>; 2], c: usize| -> PyResult<(Py<PyAny>, Py<PyAny>)> {
            let shape: &[usize] = if c == 1 { &[h, w] } else { &[h, w, c] };
            Ok((array(py, l, shape)?, array(py, r, shape)?))
        };
        let flat = |v: Vec<[f32; 3]>| v.into_iter().flatten().collect::<Vec<f32>>();
        Ok(Frame {
            left: array(py, frame.left.rgba, &[h, w, 4])?,
            right: array(py, frame.right.rgba, &[h, w, 4])?,
            depth: frame.depth.map(|d| pair(d, 1)).transpose()?,
            hdr: frame.hdr.map(|[l, r]| pair([flat(l), flat(r)], 3)).transpose()?,
            wall,
            width: w as u32,
            height: h as u32,
            stats_json: stats.to_string(),
            frame_stats: frame.stats,
            argv,
            settings,
            frame: number,
        })
    }

    /// The frame back from the arrays (as they are now), for the writer.
    fn rebuild(&self, py: Python<'_>) -> PyResult<twister::Frame> {
        let bytes = |a: &Py<PyAny>| -> PyResult<Vec<u8>> { Ok(a.bind(py).cast::<numpy::PyArray3<u8>>()?.to_vec()?) };
        let floats = |a: &Py<PyAny>| -> PyResult<Vec<f32>> {
            a.bind(py).cast::<numpy::PyUntypedArray>()?.getattr("ravel")?.call0()?.extract::<Vec<f32>>()
        };
        let image = |rgba| EyeImage { width: self.width, height: self.height, rgba };
        let depth = match &self.depth {
            Some((l, r)) => Some([floats(l)?, floats(r)?]),
            None => None,
        };
        let hdr = match &self.hdr {
            Some((l, r)) => {
                let rgb = |v: Vec<f32>| v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect::<Vec<_>>();
                Some([rgb(floats(l)?), rgb(floats(r)?)])
            }
            None => None,
        };
        Ok(twister::Frame {
            left: image(bytes(&self.left)?),
            right: image(bytes(&self.right)?),
            stats: self.frame_stats.clone(),
            measurement: None,
            depth,
            positions: None,
            hdr,
        })
    }
}

#[pymethods]
impl Frame {
    /// The fields `twister render --stats` writes, as a dict.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py.import("json")?.call_method1("loads", (&self.stats_json,))
    }

    /// Writes the files `twister render --out DIR` writes for this frame with the same settings
    /// (its images in `layout` and `format`, the sphere's metadata, depth and linear colour
    /// when drawn; a sequence's frame named as `--frames` names it), all or nothing; returns
    /// their paths.
    #[pyo3(signature = (dir, layout=None, format=None, quality=None))]
    fn save(
        &self,
        py: Python<'_>,
        dir: std::path::PathBuf,
        layout: Option<String>,
        format: Option<String>,
        quality: Option<u8>,
    ) -> PyResult<Vec<std::path::PathBuf>> {
        let mut argv = self.argv.clone();
        argv.extend(["--out".to_string(), dir.to_string_lossy().into_owned()]);
        for (flag, value) in [("--layout", layout), ("--format", format), ("--quality", quality.map(|q| q.to_string()))]
        {
            if let Some(value) = value {
                argv.extend([flag.to_string(), value]);
            }
        }
        let args = parse::<RenderCmd>(&argv)?.args;
        let frame = self.rebuild(py)?;
        let (settings, wall, number) = (self.settings, self.wall.clone(), self.frame);
        without_gil(py, move || {
            // A sequence's frames are deflated fast, as `--frames` writes them.
            let writer = twister_cli::writer::FrameWriter::new(&args, &settings, number.is_some())?.for_wall(wall);
            let files = writer.files(&frame, number)?;
            twister::output::check_outputs(&files.iter().map(|f| f.path.as_path()).collect::<Vec<_>>())?;
            twister::output::write_all(&files)?;
            Ok(files.into_iter().map(|f| f.path).collect())
        })
    }

    fn __repr__(&self) -> String {
        let wall = self.wall.as_ref().map_or(String::new(), |w| format!(", wall={w:?}"));
        format!("<twister.Frame {}x{} per eye{wall}>", self.width, self.height)
    }
}
