//! What a render returns: both eyes' images, what the frame cost and drew, and what the
//! error pass measured.

use crate::core::panoramas::projection::Eye;

/// One eye's image, tightly packed RGBA8 rows, top row first.
#[derive(Clone, Debug, Default)]
pub struct EyeImage {
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
}

impl EyeImage {
    /// The image `kx`×`ky` times smaller, each pixel the average of its block in linear light
    /// (sRGB decoded, averaged, encoded; alpha averaged as it is): the box filter that makes a
    /// larger image's samples one pixel's.
    pub fn box_filtered(&self, kx: u32, ky: u32) -> EyeImage {
        let (w, h) = (self.width / kx, self.height / ky);
        let decode: Vec<f32> =
            (0..=255).map(|b| crate::core::shading::color::srgb_to_linear(b as f32 / 255.0)).collect();
        let mut rgba = vec![0u8; (4 * w * h) as usize];
        let n = (kx * ky) as f32;
        for y in 0..h {
            for x in 0..w {
                let mut sum = [0.0f32; 4];
                for dy in 0..ky {
                    for dx in 0..kx {
                        let p = self.pixel(kx * x + dx, ky * y + dy);
                        for c in 0..3 {
                            sum[c] += decode[p[c] as usize];
                        }
                        sum[3] += p[3] as f32 / 255.0;
                    }
                }
                let i = 4 * (y * w + x) as usize;
                for c in 0..3 {
                    rgba[i + c] = (crate::core::shading::color::linear_to_srgb(sum[c] / n) * 255.0)
                        .round()
                        .clamp(0.0, 255.0) as u8;
                }
                rgba[i + 3] = (sum[3] / n * 255.0).round().clamp(0.0, 255.0) as u8;
            }
        }
        EyeImage { width: w, height: h, rgba }
    }

    pub fn pixel(&self, x: u32, y: u32) -> [u8; 4] {
        let i = 4 * (y * self.width + x) as usize;
        [self.rgba[i], self.rgba[i + 1], self.rgba[i + 2], self.rgba[i + 3]]
    }
}

/// Where a frame's times come from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Timing {
    /// GPU timestamp queries: `ms_subdivide`, `ms_raster` and `ms_gpu` are GPU times.
    GpuTimestamps,
    /// One submission timed on the wall clock: only `ms_frame` is known (the subdivision and
    /// raster were not timed apart: `ms_subdivide` and `ms_raster` are absent).
    #[default]
    WallOneSubmission,
    /// Several submissions, each pass timed on the wall clock (submit and wait).
    WallPerPass,
}

impl Timing {
    pub fn name(self) -> &'static str {
        match self {
            Timing::GpuTimestamps => "gpu-timestamps",
            Timing::WallOneSubmission => "wall-one-submission",
            Timing::WallPerPass => "wall-per-pass",
        }
    }
}

impl std::fmt::Display for Timing {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// What a render cost and drew. Times are milliseconds; [`Timing`] says how each was measured.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct FrameStats {
    pub triangles_in: u64,
    /// Triangles the subdivision produced (seam copies included), all drawn.
    pub triangles_out: u64,
    /// Nodes the subdivision produced (each piece's lattice nodes once per seam copy): the
    /// vertices the triangles index, shaded once per eye.
    pub nodes_out: u64,
    pub pieces: u64,
    /// Samples per pixel of the colour image, and how they were drawn: one at each pixel's
    /// centre, multisampled by the adapter (a pass per eye), or made up by a larger image.
    pub samples: u32,
    pub sampling: String,
    /// The ray tracer: rays traced (primary, mirror, refraction, shadow) and ray–triangle tests.
    pub rays_traced: Option<u64>,
    pub triangle_tests: Option<u64>,
    /// Largest projected length of an output edge with an end on the screen rows, pixels.
    pub max_sub_edge_px: f32,
    /// Number of `lattice` + raster rounds the scene needed to fit the memory budget.
    pub chunks: u32,
    /// The subdivision's invocations per entry point, in schedule order (a chunked frame's runs
    /// summed); empty for the slit renderer and the ray tracer.
    pub subdivide_invocations: Vec<(&'static str, u64)>,
    /// The balance of the subdivision's work: the most piece records one `plan` or `plan_cuts`
    /// invocation appended, and the most nodes or triangles (seam copies included) one
    /// `lattice` invocation wrote.
    pub max_pieces_per_invocation: u32,
    pub max_output_per_invocation: u32,
    /// Wall time of the frame's GPU work, subdivision and raster of both eyes, from the first
    /// submission until it completed (read-backs excluded).
    pub ms_frame: f64,
    pub timing: Timing,
    /// GPU time of the frame's work from timestamp queries (start of the first pass to the end
    /// of the last), where the adapter has them and the frame ran in one submission.
    pub ms_gpu: Option<f64>,
    /// The subdivision's time, where it was measured apart (see `timing`).
    pub ms_subdivide: Option<f64>,
    /// Each of the subdivision's passes, by its main entry point, in schedule order (a setup
    /// pass counted with the pass it sets up, `finalize` with the last), where timestamps
    /// measured them (their sum is within the gaps between passes of `ms_subdivide`).
    pub ms_subdivide_passes: Option<Vec<(&'static str, f64)>>,
    /// The two eyes' raster time, where it was measured apart (see `timing`).
    pub ms_raster: Option<f64>,
    /// Wall time of reading the colour targets back.
    pub ms_readback: f64,
    /// Wall time from the start of `render` to its end (read-backs and error reduction included).
    pub ms_total: f64,
}

impl FrameStats {
    /// Adds a tile's statistics to a frame's drawn in tiles: counts and times summed, the
    /// largest of the largest.
    pub fn add_tile(&mut self, tile: &FrameStats) {
        self.triangles_in = tile.triangles_in;
        self.triangles_out += tile.triangles_out;
        self.nodes_out += tile.nodes_out;
        self.pieces += tile.pieces;
        self.samples = tile.samples;
        self.sampling.clone_from(&tile.sampling);
        self.rays_traced = tile.rays_traced.map(|r| r + self.rays_traced.unwrap_or(0));
        self.triangle_tests = tile.triangle_tests.map(|r| r + self.triangle_tests.unwrap_or(0));
        self.max_sub_edge_px = self.max_sub_edge_px.max(tile.max_sub_edge_px);
        self.chunks += tile.chunks;
        self.max_pieces_per_invocation = self.max_pieces_per_invocation.max(tile.max_pieces_per_invocation);
        self.max_output_per_invocation = self.max_output_per_invocation.max(tile.max_output_per_invocation);
        self.ms_frame += tile.ms_frame;
        self.timing = tile.timing;
        let sum = |a: Option<f64>, b: Option<f64>| b.map(|b| b + a.unwrap_or(0.0));
        self.ms_gpu = sum(self.ms_gpu, tile.ms_gpu);
        self.ms_subdivide = sum(self.ms_subdivide, tile.ms_subdivide);
        self.ms_raster = sum(self.ms_raster, tile.ms_raster);
        self.ms_readback += tile.ms_readback;
        self.ms_total += tile.ms_total;
    }
}

pub struct Frame {
    pub left: EyeImage,
    pub right: EyeImage,
    pub stats: FrameStats,
    /// The error pass's outputs, when `RenderSettings::measure.error` was set.
    pub measurement: Option<Measurement>,
    /// Per pixel, left and right eye: the distance in metres from the pixel's eye point to the
    /// surface it shows (+∞: background), when `RenderSettings::measure.depth` was set.
    pub depth: Option<[Vec<f32>; 2]>,
    /// Per pixel, left and right eye: the surface point it shows, viewer frame (the drawing
    /// stages' interpolated `view_position`; NaN: background), when
    /// `RenderSettings::measure.positions` was set.
    pub positions: Option<[Vec<[f32; 3]>; 2]>,
    /// Per pixel, left and right eye: the linear colour × 2^EV (RGB, not tone mapped, not
    /// clamped), when `RenderSettings::shading.hdr` was set: drawn in the same passes as `left`
    /// and `right`, which are the same frame tone mapped.
    pub hdr: Option<[Vec<[f32; 3]>; 2]>,
}

/// What the error pass measured (seed 002 §4.1).
pub struct Measurement {
    /// Display-position error per pixel, left and right eye (−1: background or unseen).
    pub error: [Vec<f32>; 2],
    /// Object id + 1 per pixel, left and right eye (0: background).
    pub object: [Vec<u32>; 2],
    /// The GPU reduction of `error` over both eyes.
    pub stats: ErrorStats,
}

impl Frame {
    pub fn eye(&self, eye: Eye) -> &EyeImage {
        match eye {
            Eye::Left => &self.left,
            Eye::Right => &self.right,
        }
    }
}

/// The display-position error's statistics over a frame's pixels (`ErrorStats` in
/// shaders/reduce_error.wgsl, which computes them; laid out as WGSL reads it).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable, serde::Serialize)]
pub struct ErrorStats {
    pub count: u32,
    pub mean: f32,
    pub std_dev: f32,
    pub p50: f32,
    pub p90: f32,
    pub p99: f32,
    pub max: f32,
    #[serde(skip)]
    pub _pad: f32,
}
