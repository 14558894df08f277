//! One frame writer for a still and for each frame of a sequence: which files a frame makes
//! (the layout's images, depth, linear colour), how they are encoded and named, and the
//! statistics record written beside them (`--stats`: one JSON object for a still, one line per
//! frame for a sequence).

use std::path::PathBuf;

use serde::Serialize;
use twister::core::frame::FrameStats;
use twister::core::panoramas::projection::PanoramaKind;
use twister::error::{Error, Result};
use twister::output::{
    depth_images, depth_names, exr_file, gpano_xmp, hdr_exr_file, image_file, layout_images, layout_names,
    transparent_outside, Encoding, ImageFormat, Layout, OutputFile,
};
use twister::{Frame, RenderSettings};

use crate::args::RenderArgs;

/// The linear colour's files (`--hdr`), per eye.
const HDR_NAMES: [&str; 2] = ["left_hdr.exr", "right_hdr.exr"];

/// How a render's frames become files.
#[derive(Clone)]
pub struct FrameWriter {
    out: PathBuf,
    /// A CAVE's wall: its name prefixes every file (`front_left.png`).
    wall: Option<String>,
    layout: Layout,
    /// The panorama drawn: its tag goes into the combined layouts' names.
    panorama: PanoramaKind,
    /// The images' format and how they are encoded.
    encoding: Encoding,
    depth: bool,
    hdr: bool,
    /// The fisheye with `--alpha`: its projection, whose circle's outside is made transparent.
    transparent_outside: Option<twister::Projection>,
}

impl FrameWriter {
    /// The writer the options ask for, for frames drawn with `settings`; `fast`: PNGs deflated
    /// quickly (sequences).
    pub fn new(args: &RenderArgs, settings: &RenderSettings, fast: bool) -> Result<FrameWriter> {
        if args.quality.is_some() && args.format != ImageFormat::Jpg {
            return Err(Error::option("--quality", "needs --format jpg"));
        }
        let projection = settings.projection();
        let sphere = projection.panorama.is_equirectangular();
        if args.alpha && projection.panorama != PanoramaKind::Fisheye {
            return Err(Error::option("--alpha", "needs --panorama fisheye (the outside of its circle)"));
        }
        if args.alpha && args.format != ImageFormat::Png {
            return Err(Error::option("--alpha", "needs --format png (JPEG has no alpha)"));
        }
        if args.layout == Some(Layout::Twister) && !projection.panorama.wraps() {
            return Err(Error::option(
                "--layout",
                format!(
                    "twister splits a panorama that goes all around; --panorama {} spans 180°",
                    projection.panorama.name()
                ),
            ));
        }
        if args.layout == Some(Layout::Strip12) && projection.panorama != PanoramaKind::Cubemap {
            return Err(Error::option("--layout", "12x1 lays out a cubemap's faces: use it with --panorama cubemap"));
        }
        Ok(FrameWriter {
            out: args.out.clone(),
            wall: None,
            layout: args.layout.unwrap_or(Layout::default_for(projection.panorama)),
            panorama: projection.panorama,
            encoding: Encoding {
                format: args.format,
                quality: args.quality.unwrap_or(90),
                xmp: sphere.then(|| gpano_xmp(projection.panorama, projection.width, projection.height)),
                fast,
            },
            depth: args.depth,
            hdr: args.hdr,
            transparent_outside: args.alpha.then_some(*projection),
        })
    }

    pub fn layout(&self) -> Layout {
        self.layout
    }

    /// The CAVE wall this writer's files are named by, if any.
    pub fn wall(&self) -> Option<&str> {
        self.wall.as_deref()
    }

    /// The writer of a CAVE's wall: the same files, each name prefixed by the wall's.
    pub fn for_wall(&self, wall: Option<String>) -> FrameWriter {
        FrameWriter { wall, ..self.clone() }
    }

    /// The layout's image names (`left.png`, `stereo_TB.png`, …).
    pub fn image_names(&self) -> Vec<String> {
        layout_names(self.layout, self.encoding.format, self.panorama)
    }

    /// Where a file of a frame goes: as named for a still, numbered for frame `k` of a sequence.
    fn path(&self, frame: Option<u32>, name: &str) -> PathBuf {
        let name = &match &self.wall {
            Some(wall) => format!("{wall}_{name}"),
            None => name.to_string(),
        };
        self.out.join(match frame {
            Some(k) => frame_name(k, name),
            None => name.to_string(),
        })
    }

    /// Every file a frame writes, the images first.
    pub fn paths(&self, frame: Option<u32>) -> Vec<PathBuf> {
        let mut names = self.image_names();
        if self.depth {
            names.extend(depth_names(self.layout));
        }
        if self.hdr {
            names.extend(HDR_NAMES.map(String::from));
        }
        names.iter().map(|name| self.path(frame, name)).collect()
    }

    /// Image `image` of the layout (a still's), encoded into `temp` (the output `path`) row by
    /// row from eyes of `eye_size` whose rows `read(eye, row, first column, columns)` gives
    /// (RGBA): a tiled frame's images, streamed (`output::stream_image`); the fisheye's outside
    /// made transparent with `--alpha`.
    pub fn stream_image(
        &self,
        image: usize,
        path: &std::path::Path,
        temp: &std::path::Path,
        eye_size: [u32; 2],
        read: &mut dyn FnMut(usize, u32, u32, u32) -> Result<Vec<u8>>,
    ) -> Result<()> {
        let size = twister::output::layout_sizes(self.layout, eye_size)[image];
        twister::output::stream_image(path, temp, size, &self.encoding, |row| {
            let mut rgba = Vec::with_capacity(4 * size[0] as usize);
            for (eye, src_row, x0, n) in twister::output::layout_row(self.layout, image, row, eye_size) {
                let mut piece = read(eye, src_row, x0, n)?;
                if let Some(projection) = &self.transparent_outside {
                    for (k, px) in piece.chunks_exact_mut(4).enumerate() {
                        if !projection.shows_pixel((x0 + k as u32) as f32 + 0.5, src_row as f32 + 0.5) {
                            px.copy_from_slice(&[0; 4]);
                        }
                    }
                }
                rgba.extend_from_slice(&piece);
            }
            Ok(rgba)
        })
    }

    /// The depth files' names of the layout (the eyes apart for the layouts of several images).
    pub fn depth_names(&self) -> Vec<String> {
        depth_names(self.depth_layout())
    }

    /// The layout the depth files follow: the eyes apart for the display's four halves.
    fn depth_layout(&self) -> Layout {
        match self.layout {
            Layout::Twister => Layout::Eyes,
            other => other,
        }
    }

    /// Depth file `file` of the layout, encoded into `temp` row by row from eyes of `eye_size`
    /// whose rows `read(eye, row, first column, columns)` gives (metres): a tiled frame's.
    pub fn stream_depth(
        &self,
        file: usize,
        path: &std::path::Path,
        temp: &std::path::Path,
        eye_size: [u32; 2],
        read: &mut (dyn FnMut(usize, u32, u32, u32) -> Result<Vec<f32>> + Send),
    ) -> Result<()> {
        let layout = self.depth_layout();
        let size = twister::output::layout_sizes(layout, eye_size)[file];
        twister::output::stream_exr(path, temp, size, 1, |row| {
            let mut values = Vec::with_capacity(size[0] as usize);
            for (eye, src_row, x0, n) in twister::output::layout_row(layout, file, row, eye_size) {
                values.extend(read(eye, src_row, x0, n)?);
            }
            Ok(values)
        })
    }

    /// A frame's files, encoded: the layout's images, then depth and linear colour where the
    /// frame holds them.
    pub fn files(&self, rendered: &Frame, frame: Option<u32>) -> Result<Vec<OutputFile>> {
        // The images are encoded side by side (a still's two eyes: half the wait on two cores).
        let images = match &self.transparent_outside {
            None => layout_images(rendered, self.layout, self.encoding.format, self.panorama),
            Some(projection) => {
                let [left, right] = [&rendered.left, &rendered.right].map(|img| transparent_outside(img, projection));
                let eyes = Frame {
                    left,
                    right,
                    stats: Default::default(),
                    measurement: None,
                    depth: None,
                    positions: None,
                    hdr: None,
                };
                layout_images(&eyes, self.layout, self.encoding.format, self.panorama)
            }
        };
        let mut files = std::thread::scope(|scope| {
            let encoders: Vec<_> = images
                .iter()
                .map(|(name, img)| {
                    let path = self.path(frame, name);
                    scope.spawn(move || image_file(path, img, &self.encoding))
                })
                .collect();
            encoders.into_iter().map(|e| e.join().expect("an image encoder panicked")).collect::<Result<Vec<_>>>()
        })?;
        for (name, depth) in depth_images(rendered, self.layout).unwrap_or_default() {
            files.push(exr_file(self.path(frame, &name), &depth)?);
        }
        if let Some(hdr) = &rendered.hdr {
            for (name, eye) in HDR_NAMES.into_iter().zip(hdr) {
                files.push(hdr_exr_file(self.path(frame, name), rendered.left.width, rendered.left.height, eye)?);
            }
        }
        Ok(files)
    }
}

/// A frame's file name: `frame_000123_` and the layout's name (`stereo_` dropped: `_TB`, `_LR`).
pub fn frame_name(frame: u32, layout_name: &str) -> String {
    format!("frame_{frame:06}_{}", layout_name.strip_prefix("stereo_").unwrap_or(layout_name))
}

/// What `--stats` records of a frame: the scene, the method and its parameters, the view, and
/// the frame's own [`FrameStats`] (counts and times, flattened into the record). A sequence's
/// lines also carry the frame, its time, the pose's time and the files written.
#[derive(Serialize)]
pub struct FrameRecord<'a> {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub frame: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time: Option<f32>,
    /// A CAVE's wall.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub wall: Option<String>,
    /// A frame drawn in tiles: how many.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tiles: Option<u32>,
    pub scene: &'a str,
    pub method: String,
    pub edge_px: f32,
    pub max_error_px: f32,
    pub max_div: u32,
    #[serde(flatten)]
    pub stats: &'a FrameStats,
    /// The triangles drawn (the subdivision's output, `triangles_out`).
    pub triangles_drawn: u64,
    pub width: u32,
    pub height: u32,
    pub screen_radius: f32,
    pub eye_radius: f32,
    pub vertical: twister::Vertical,
    pub panorama: PanoramaKind,
    pub convergence: serde_json::Value,
    pub pole_merge: Option<(f32, f32)>,
    pub layout: Layout,
    pub format: ImageFormat,
    pub adapter: &'a str,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ms_pose: Option<f64>,
    pub ms_write: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub files: Option<Vec<String>>,
    pub lod: serde_json::Value,
}

impl<'a> FrameRecord<'a> {
    /// The record of `rendered`, drawn from `scene` with `settings`, written by `writer`.
    pub fn new(
        scene: &'a str,
        settings: &RenderSettings,
        rendered: &'a Frame,
        writer: &FrameWriter,
        adapter: &'a str,
        lod: serde_json::Value,
    ) -> FrameRecord<'a> {
        let (s, p, sub) = (&rendered.stats, settings.projection(), &settings.subdivision);
        FrameRecord {
            frame: None,
            time: None,
            wall: writer.wall.clone(),
            tiles: None,
            scene,
            method: sub.method.name(),
            edge_px: sub.edge_px,
            max_error_px: sub.max_error_px,
            max_div: sub.max_div,
            stats: s,
            triangles_drawn: s.triangles_out,
            width: p.width,
            height: p.height,
            screen_radius: p.screen_radius,
            eye_radius: p.eye_radius,
            vertical: p.vertical,
            panorama: p.panorama,
            convergence: p.convergence.map_or(serde_json::json!("parallel"), |c| serde_json::json!(c)),
            pole_merge: p.pole_merge,
            layout: writer.layout,
            format: writer.encoding.format,
            adapter,
            ms_pose: None,
            ms_write: 0.0,
            files: None,
            lod,
        }
    }
}
