//! `twister render`: both eyes' panoramas of a scene, written as a layout of PNGs, with
//! optional statistics.

use std::path::PathBuf;

use clap::Args;

use crate::args::{parse_rgb, LodMode, ViewArgs};
use crate::scene::{lod_stats, open_renderer, prepare};
use twister::core::projection::PanoramaKind;
use twister::core::settings::Method;
use twister::error::{Error, Result};
use twister::output::{
    check_outputs, depth_images, depth_names, exr_file, gpano_xmp, hdr_exr_file, image_file, layout_images,
    layout_names, write_all, Encoding, ImageFormat, Layout, OutputFile,
};

#[derive(Args)]
#[command(allow_negative_numbers = true)]
pub struct RenderArgs {
    /// Scene to render: a .obj, .gltf or .glb file, or builtin:demo, builtin:box-room, builtin:cube, builtin:sphere100, builtin:sphere1024, builtin:triangle@D.
    #[arg(default_value = "builtin:demo")]
    pub scene: String,
    /// Move and scale the scene so that it stands DIST metres ahead, filling the screen height.
    #[arg(long, value_name = "DIST")]
    pub fit: Option<f32>,
    /// Output folder.
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    #[command(flatten)]
    pub view: ViewArgs,
    /// Output layout: eyes (left.png, right.png), top-bottom (stereo_TB.png, left eye on top),
    /// side-by-side (stereo_LR.png, left eye on the left), twister (four W/2×H images)
    /// [default: eyes; top-bottom for --panorama equirect].
    #[arg(long, value_enum)]
    pub layout: Option<Layout>,
    /// Image format: png or jpg (full-sphere images carry GPano XMP metadata in both).
    #[arg(long, value_enum, default_value_t = ImageFormat::Png)]
    pub format: ImageFormat,
    /// JPEG quality, 1–100 (with --format jpg).
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=100))]
    pub quality: Option<u8>,
    /// Also write each eye's distance from its eye point along the ray, metres, as 32-bit float
    /// OpenEXR (channel Z, +inf where no surface): left_depth.exr/right_depth.exr, depth_TB.exr
    /// or depth_LR.exr, following the layout.
    #[arg(long)]
    pub depth: bool,
    /// Also write each eye's linear colour (× 2^EV, before tone mapping, not clamped) as 32-bit
    /// float OpenEXR (channels R, G, B): left_hdr.exr, right_hdr.exr. A second frame is drawn
    /// into a float colour target; the projection methods only.
    #[arg(long)]
    pub hdr: bool,
    /// Background colour R,G,B, each 0–255.
    #[arg(long, value_parser = parse_rgb, default_value = "26,26,31")]
    pub background: [f32; 3],
    /// Write render statistics as JSON to this file.
    #[arg(long)]
    pub stats: Option<PathBuf>,
    /// With --lod visual-field: tint each object by its level and draw the central-field
    /// (white) and visual-field (orange) boundaries.
    #[arg(long)]
    pub lod_overlay: bool,
    /// Render frames A to B (inclusive) of the animation timeline (frame k at k / FPS seconds)
    /// into numbered files: frame_000123_TB.png (top-bottom), frame_000123_left.png … (see
    /// *Sequences* in the README); `N` alone renders frame N.
    #[arg(long, value_parser = crate::sequence::parse_frames, value_name = "A..B")]
    pub frames: Option<(u32, u32)>,
    /// Frames per second of the sequence's timeline.
    #[arg(long, default_value_t = 30.0)]
    pub fps: f32,
    /// The animation a sequence plays, by name or index [default: the file's first].
    #[arg(long, value_name = "NAME|INDEX")]
    pub animation: Option<String>,
    /// Skip the frames whose files all exist (a sequence resumed after a stop).
    #[arg(long)]
    pub resume: bool,
    /// Render only this shard's frames: I/N, frames whose index from A is ≡ I (mod N), or the
    /// I-th of N contiguous blocks with --shard-mode blocks (a job array's task id).
    #[arg(long, value_parser = crate::sequence::parse_shard, value_name = "I/N")]
    pub shard: Option<(u32, u32)>,
    /// With --frames: also encode the sequence as an MP4 video (H.264 by the system's ffmpeg)
    /// with Google's spherical video metadata (st3d stereo mode; sv3d equirectangular on the
    /// sphere); needs a one-image layout (top-bottom or side-by-side). After --shard runs, run
    /// once more with --resume --video to encode.
    #[arg(long, value_name = "FILE.mp4")]
    pub video: Option<PathBuf>,
    /// With --frames and --lod visual-field: the gaze over time, a CSV of time,yaw,pitch rows
    /// (seconds, degrees as --gaze): each frame's level of detail follows the tracked viewer.
    #[arg(long, value_name = "FILE.csv")]
    pub gaze_path: Option<PathBuf>,
    /// With --frames: the viewer over time, a CSV of time,x,y,z[,yaw] rows (seconds; the place
    /// in scene units as --viewer; degrees added to --yaw), blended linearly between rows.
    #[arg(long, value_name = "FILE.csv")]
    pub viewer_path: Option<PathBuf>,
    /// How --shard splits the frames.
    #[arg(long, value_enum, default_value_t = crate::sequence::ShardMode::Interleave)]
    pub shard_mode: crate::sequence::ShardMode,
}

pub fn render(args: &RenderArgs) -> Result<()> {
    let mut settings = args.view.settings(&[args.view.method])?;
    settings.shading.background = args.background;
    if let Some(frames) = args.frames {
        return crate::sequence::render_sequence(args, frames, settings);
    }
    for (given, option) in [
        (args.resume, "--resume"),
        (args.shard.is_some(), "--shard"),
        (args.animation.is_some(), "--animation"),
        (args.video.is_some(), "--video"),
        (args.gaze_path.is_some(), "--gaze-path"),
        (args.viewer_path.is_some(), "--viewer-path"),
    ] {
        if given {
            return Err(Error::option(option, "belongs to a sequence: use it with --frames A..B"));
        }
    }
    settings.measure.edges = args.stats.is_some();
    settings.measure.depth = args.depth;
    let panorama = settings.projection().panorama;
    let layout = args.layout.unwrap_or(Layout::default_for(panorama));
    if args.quality.is_some() && args.format != ImageFormat::Jpg {
        return Err(Error::option("--quality", "needs --format jpg"));
    }
    let (w, h) = (settings.projection().width, settings.projection().height);
    let encoding = Encoding {
        format: args.format,
        quality: args.quality.unwrap_or(90),
        xmp: (panorama == PanoramaKind::Equirect).then(|| gpano_xmp(w, h)),
        fast: false,
    };
    if args.lod_overlay && args.view.lod == LodMode::Off {
        return Err(Error::option("--lod-overlay", "needs --lod visual-field"));
    }
    // Every output is checked before anything is rendered, and all are written together.
    let mut image_paths: Vec<PathBuf> =
        layout_names(layout, args.format).iter().map(|name| args.out.join(name)).collect();
    if args.depth {
        image_paths.extend(depth_names(layout).iter().map(|name| args.out.join(name)));
    }
    if args.hdr {
        if matches!(settings.subdivision.method, Method::Slit(_) | Method::Trace) {
            return Err(Error::option(
                "--hdr",
                "the linear colour comes from the projection methods (vertex, fixed, adaptive); slit and trace write display colours",
            ));
        }
        image_paths.extend(["left_hdr.exr", "right_hdr.exr"].map(|name| args.out.join(name)));
    }
    let mut all_paths: Vec<&std::path::Path> = image_paths.iter().map(PathBuf::as_path).collect();
    all_paths.extend(args.stats.as_deref());
    check_outputs(&all_paths)?;
    let (renderer, adapter) = open_renderer()?;
    let method = [settings.subdivision.method];
    let prepared = prepare(&renderer, &args.scene, args.fit, &args.view, &mut settings, args.lod_overlay, &method)?;
    let mut frame = renderer.render(&prepared.gpu_scene, &settings)?;
    if let (true, Some(gaze)) = (args.lod_overlay, &prepared.gaze) {
        for img in [&mut frame.left, &mut frame.right] {
            twister::core::lod::draw_field_boundaries(img, settings.projection(), gaze);
        }
    }
    let t = std::time::Instant::now();
    let mut files = layout_images(&frame, layout, args.format)
        .iter()
        .map(|(name, img)| image_file(args.out.join(name), img, &encoding))
        .collect::<Result<Vec<_>>>()?;
    for (name, depth) in depth_images(&frame, layout).unwrap_or_default() {
        files.push(exr_file(args.out.join(name), &depth)?);
    }
    if args.hdr {
        let hdr = renderer.render(&prepared.gpu_scene, &settings.with_hdr(true))?.hdr.expect("an HDR frame");
        for (name, eye) in ["left_hdr.exr", "right_hdr.exr"].into_iter().zip(&hdr) {
            files.push(hdr_exr_file(args.out.join(name), w, h, eye)?);
        }
    }
    // Encoding: the writing itself is a rename.
    let ms_write = t.elapsed().as_secs_f64() * 1e3;
    if let Some(path) = &args.stats {
        let s = &frame.stats;
        let json = serde_json::json!({
            "scene": args.scene,
            "method": settings.subdivision.method.name(),
            "edge_px": settings.subdivision.edge_px,
            "max_error_px": settings.subdivision.max_error_px,
            "max_div": settings.subdivision.max_div,
            "triangles_in": s.triangles_in,
            "triangles_out": s.triangles_out,
            "triangles_drawn": s.triangles_out,
            "pieces": s.pieces,
            "rays_traced": s.rays_traced,
            "triangle_tests": s.triangle_tests,
            "max_sub_edge_px": s.max_sub_edge_px,
            "chunks": s.chunks,
            "width": settings.view.projection.width,
            "height": settings.view.projection.height,
            "screen_radius": settings.view.projection.screen_radius,
            "eye_radius": settings.view.projection.eye_radius,
            "vertical": settings.view.projection.vertical,
            "panorama": panorama,
            "convergence": settings.view.projection.convergence.map_or(serde_json::json!("parallel"), |c| serde_json::json!(c)),
            "pole_merge": settings.view.projection.pole_merge,
            "layout": layout,
            "format": args.format,
            "adapter": adapter,
            "timing": s.timing,
            "ms_frame": s.ms_frame,
            "ms_gpu": s.ms_gpu,
            "ms_subdivide": s.ms_subdivide,
            "ms_raster": s.ms_raster,
            "ms_readback": s.ms_readback,
            "ms_write": ms_write,
            "ms_total": s.ms_total + ms_write,
            "lod": lod_stats(&prepared.selection),
        });
        let text = serde_json::to_string_pretty(&json).expect("JSON of plain values");
        files.push(OutputFile { path: path.clone(), bytes: text.into_bytes() });
    }
    write_all(&files)?;
    for f in files.iter().take(image_paths.len()) {
        println!("{}", f.path.display());
    }
    Ok(())
}
