//! The benchmark charts, drawn with plotters: line series with markers and ±std error bars,
//! linear or logarithmic axes, categorical or numeric ticks, dashed reference lines, a legend
//! in a column beside the plot. Text uses a TrueType font found on the system (DejaVu Sans, or
//! the file named by `TWISTER_FONT`), registered with plotters once; without one the charts are
//! drawn without text.

use std::ops::Range;
use std::sync::OnceLock;

use image::RgbaImage;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;

/// Colours for series, in order (colour-blind friendly).
pub const PALETTE: [[u8; 3]; 8] = [
    [0, 114, 178],
    [213, 94, 0],
    [0, 158, 115],
    [204, 121, 167],
    [230, 159, 0],
    [86, 180, 233],
    [120, 120, 120],
    [0, 0, 0],
];

const FONT_PATHS: [&str; 5] = [
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
    "/Library/Fonts/Arial.ttf",
];

/// The font family registered for chart text, if a font could be loaded.
pub fn font() -> Option<&'static str> {
    static FONT: OnceLock<Option<&'static str>> = OnceLock::new();
    *FONT.get_or_init(|| {
        let candidates: Vec<String> =
            std::env::var("TWISTER_FONT").into_iter().chain(FONT_PATHS.iter().map(|p| p.to_string())).collect();
        candidates.iter().filter_map(|p| std::fs::read(p).ok()).find_map(|bytes| {
            // Registered once for the process: plotters keeps `'static` font data.
            let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
            plotters::style::register_font("twister", FontStyle::Normal, bytes).ok().map(|_| "twister")
        })
    })
}

#[derive(Clone, Debug)]
pub struct Series {
    pub label: String,
    /// (x, y, ± error bar); points with a non-finite or (on a log axis) non-positive y are skipped.
    pub points: Vec<(f64, f64, Option<f64>)>,
    pub color: [u8; 3],
    pub dashed: bool,
    pub markers: bool,
}

#[derive(Clone, Debug, Default)]
pub struct Chart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub x_log: bool,
    pub y_log: bool,
    /// Tick positions and labels for x (e.g. method names); automatic if empty.
    pub x_ticks: Vec<(f64, String)>,
    pub series: Vec<Series>,
}

/// The range an axis shows: the data, from 0 (linear) or whole decades (log), with a margin.
fn axis_range(values: impl Iterator<Item = f64>, log: bool) -> Range<f64> {
    let v: Vec<f64> = values.filter(|x| x.is_finite() && (!log || *x > 0.0)).collect();
    let (mut lo, mut hi) = v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| (a.min(x), b.max(x)));
    if !lo.is_finite() {
        return if log { 0.1..10.0 } else { 0.0..1.0 };
    }
    if log {
        lo = 10f64.powf(lo.log10().floor());
        hi = 10f64.powf(hi.log10().ceil());
        if hi <= lo {
            hi = lo * 10.0;
        }
    } else {
        lo = lo.min(0.0);
        let pad = (hi - lo).abs().max(1e-9) * 0.08;
        hi += pad;
        if lo < 0.0 {
            lo -= pad;
        }
    }
    lo..hi
}

fn color(c: [u8; 3]) -> RGBColor {
    RGBColor(c[0], c[1], c[2])
}

fn format_number(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        "0".into()
    } else if !(0.001..1000.0).contains(&a) {
        format!("{v:.0e}")
    } else if a >= 10.0 {
        format!("{v:.0}")
    } else if a >= 1.0 {
        format!("{v:.1}").trim_end_matches(".0").to_string()
    } else {
        format!("{v:.3}").trim_end_matches('0').to_string()
    }
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;

/// Draws one chart into a panel, with the given x and y coordinate specs (linear or log).
fn draw_chart<'a, X, Y>(area: &Area<'a>, chart: &Chart, x: X, y: Y) -> Result<(), String>
where
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let err = |e: DrawingAreaErrorKind<_>| e.to_string();
    let font = font();
    let legend_w = if font.is_some() && !chart.series.is_empty() {
        chart.series.iter().map(|s| s.label.chars().count() as u32 * 7 + 44).max().unwrap_or(0)
    } else {
        0
    };
    let (w, _) = area.dim_in_pixel();
    let (plot_area, legend_area) = area.split_horizontally(w.saturating_sub(legend_w));
    let mut builder = ChartBuilder::on(&plot_area);
    builder.margin(12).x_label_area_size(48).y_label_area_size(64);
    if let Some(f) = font {
        builder.caption(&chart.title, (f, 18));
    }
    let mut ctx = builder.build_cartesian_2d(x, y).map_err(err)?;
    let ticks = chart.x_ticks.clone();
    let x_format = move |v: &f64| {
        if ticks.is_empty() {
            format_number(*v)
        } else {
            ticks.iter().find(|(t, _)| (t - v).abs() < 1e-6).map_or(String::new(), |(_, l)| l.clone())
        }
    };
    let mut mesh = ctx.configure_mesh();
    mesh.light_line_style(RGBColor(235, 235, 235)).bold_line_style(RGBColor(215, 215, 215));
    mesh.x_label_formatter(&x_format).y_label_formatter(&|v| format_number(*v));
    if !chart.x_ticks.is_empty() {
        mesh.x_labels(4 * chart.x_ticks.len() + 1);
    }
    match font {
        Some(f) => {
            mesh.x_desc(&chart.x_label).y_desc(&chart.y_label).label_style((f, 13)).axis_desc_style((f, 14));
        }
        None => {
            mesh.x_labels(0).y_labels(0);
        }
    }
    mesh.draw().map_err(err)?;
    let shown = |y: f64| y.is_finite() && (!chart.y_log || y > 0.0);
    for s in &chart.series {
        let style = color(s.color).stroke_width(2);
        let pts: Vec<(f64, f64)> = s.points.iter().filter(|p| shown(p.1)).map(|p| (p.0, p.1)).collect();
        if s.dashed {
            ctx.draw_series(DashedLineSeries::new(pts.clone(), 6, 4, style)).map_err(err)?;
        } else {
            ctx.draw_series(LineSeries::new(pts.clone(), style)).map_err(err)?;
        }
        let bars = s.points.iter().filter(|p| shown(p.1)).filter_map(|&(x, y, e)| {
            let e = e.filter(|e| *e > 0.0)?;
            let lo = if chart.y_log { (y - e).max(y * 1e-3) } else { y - e };
            Some(ErrorBar::new_vertical(x, lo, y, y + e, color(s.color).stroke_width(1), 8))
        });
        ctx.draw_series(bars).map_err(err)?;
        if s.markers {
            ctx.draw_series(pts.iter().map(|&p| Circle::new(p, 4, color(s.color).filled()))).map_err(err)?;
        }
    }
    // The legend, in its own column so it never hides data.
    if let Some(f) = font {
        draw_legend(&legend_area, chart, f)?;
    }
    Ok(())
}

/// The series' legend: a line (dashed like its series) and the label, one row each.
fn draw_legend(legend_area: &Area, chart: &Chart, f: &str) -> Result<(), String> {
    let err = |e: DrawingAreaErrorKind<_>| e.to_string();
    for (k, s) in chart.series.iter().enumerate() {
        let y = 60 + 20 * k as i32;
        let line = color(s.color).stroke_width(2);
        if s.dashed {
            for d in 0..3 {
                legend_area.draw(&PathElement::new([(4 + 8 * d, y), (8 + 8 * d, y)], line)).map_err(err)?;
            }
        } else {
            legend_area.draw(&PathElement::new([(4, y), (28, y)], line)).map_err(err)?;
        }
        legend_area.draw(&Text::new(s.label.clone(), (34, y - 7), (f, 13).into_font())).map_err(err)?;
    }
    Ok(())
}

/// Draws charts in a grid of `columns`, each panel w × h pixels, on a white background.
pub fn draw_panels(charts: &[Chart], columns: usize, w: u32, h: u32) -> RgbaImage {
    let columns = columns.max(1);
    let rows = charts.len().div_ceil(columns).max(1);
    let (width, height) = (w * columns as u32, h * rows as u32);
    let mut rgb = vec![255u8; (3 * width * height) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (width, height)).into_drawing_area();
        let panels = root.split_evenly((rows, columns));
        for (chart, area) in charts.iter().zip(&panels) {
            let xs: Vec<f64> = chart
                .series
                .iter()
                .flat_map(|s| s.points.iter().map(|p| p.0))
                .chain(chart.x_ticks.iter().map(|t| t.0))
                .collect();
            let ys = chart.series.iter().flat_map(|s| {
                s.points.iter().flat_map(|&(_, y, e)| {
                    [y, y + e.unwrap_or(0.0), if chart.y_log { y } else { y - e.unwrap_or(0.0) }]
                })
            });
            let mut xr = axis_range(xs.iter().copied(), chart.x_log);
            if !chart.x_ticks.is_empty() && !chart.x_log {
                let (lo, hi) =
                    chart.x_ticks.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), t| (a.min(t.0), b.max(t.0)));
                xr = lo - 0.5..hi + 0.5;
            }
            let yr = axis_range(ys, chart.y_log);
            let drawn = match (chart.x_log, chart.y_log) {
                (false, false) => draw_chart(area, chart, xr, yr),
                (false, true) => draw_chart(area, chart, xr, yr.log_scale()),
                (true, false) => draw_chart(area, chart, xr.log_scale(), yr),
                (true, true) => draw_chart(area, chart, xr.log_scale(), yr.log_scale()),
            };
            // A chart that cannot be drawn leaves its panel blank rather than failing the report.
            if let Err(e) = drawn {
                eprintln!("warning: chart '{}' not drawn: {e}", chart.title);
            }
        }
        let _ = root.present();
    }
    let rgba: Vec<u8> = rgb.chunks(3).flat_map(|p| [p[0], p[1], p[2], 255]).collect();
    RgbaImage::from_raw(width, height, rgba).expect("size matches")
}

/// Draws `text` in white onto an RGB buffer of `width` × `height` at (x, y), `size` pixels high;
/// nothing without a font.
pub fn label(rgb: &mut [u8], width: u32, height: u32, x: i32, y: i32, size: u32, text: &str) {
    let Some(f) = font() else { return };
    let root = BitMapBackend::with_buffer(rgb, (width, height)).into_drawing_area();
    let _ = root.draw(&Text::new(text.to_string(), (x, y), (f, size).into_font().color(&WHITE)));
    let _ = root.present();
}

/// The width in pixels `text` takes at `size` (an estimate without a font).
pub fn label_width(size: u32, text: &str) -> u32 {
    match font() {
        Some(f) => (f, size).into_font().box_size(text).map_or(0, |(w, _)| w),
        None => size / 2 * text.chars().count() as u32,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chart(y_log: bool, dashed: bool) -> Chart {
        Chart {
            title: "t".into(),
            y_log,
            x_ticks: vec![(1.0, "a".into()), (2.0, "b".into()), (3.0, "c".into())],
            series: vec![Series {
                label: "a".into(),
                points: vec![(1.0, 0.05, Some(0.01)), (2.0, 30.0, None), (3.0, f64::NAN, None)],
                color: PALETTE[1],
                dashed,
                markers: true,
            }],
            ..Default::default()
        }
    }

    #[test]
    fn charts_draw_their_series_on_every_axis_kind() {
        for (y_log, dashed) in [(true, false), (false, true)] {
            let img = draw_panels(&[chart(y_log, dashed), chart(!y_log, !dashed)], 2, 400, 300);
            assert_eq!(img.dimensions(), (800, 300));
            // The series colour appears in both panels (markers and the line were drawn).
            let c = PALETTE[1];
            for half in [0..400, 400..800] {
                let n = img.enumerate_pixels().filter(|(x, _, p)| half.contains(x) && p.0[..3] == c).count();
                assert!(n > 50, "{n} series pixels in {half:?}");
            }
        }
        let r = axis_range([0.05, 30.0].into_iter(), true);
        assert!(r.start <= 0.05 && r.end >= 30.0);
        let r = axis_range([2.0, 7.0].into_iter(), false);
        assert!(r.start == 0.0 && r.end > 7.0);
    }
}
