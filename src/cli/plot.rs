//! Small PNG charts for the benchmarks: line series with markers and ±std error bars,
//! linear or logarithmic axes, categorical or numeric ticks, dashed reference lines, a legend.
//! Drawing uses `imageproc`; text uses a TrueType font found on the system (DejaVu Sans, or
//! the file named by `TWISTER_FONT`). Without a font the charts are drawn without text.

use std::sync::OnceLock;

use ab_glyph::{FontArc, PxScale};
use image::{Rgba, RgbaImage};
use imageproc::drawing::{
    draw_filled_circle_mut, draw_filled_rect_mut, draw_line_segment_mut, draw_text_mut, text_size,
};
use imageproc::rect::Rect;

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

/// The font used for chart text, if one could be loaded.
pub fn font() -> Option<&'static FontArc> {
    static FONT: OnceLock<Option<FontArc>> = OnceLock::new();
    FONT.get_or_init(|| {
        let candidates: Vec<String> =
            std::env::var("TWISTER_FONT").into_iter().chain(FONT_PATHS.iter().map(|p| p.to_string())).collect();
        candidates.iter().filter_map(|p| std::fs::read(p).ok()).find_map(|bytes| FontArc::try_from_vec(bytes).ok())
    })
    .as_ref()
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

struct Axis {
    lo: f64,
    hi: f64,
    log: bool,
}

impl Axis {
    fn fit(values: impl Iterator<Item = f64>, log: bool) -> Axis {
        let v: Vec<f64> = values.filter(|x| x.is_finite() && (!log || *x > 0.0)).collect();
        let (mut lo, mut hi) = v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| (a.min(x), b.max(x)));
        if !lo.is_finite() {
            (lo, hi) = if log { (0.1, 10.0) } else { (0.0, 1.0) };
        }
        if log {
            lo = 10f64.powf(lo.log10().floor());
            hi = 10f64.powf(hi.log10().ceil());
            if hi <= lo {
                hi = lo * 10.0;
            }
        } else {
            if lo > 0.0 {
                lo = 0.0;
            }
            let pad = (hi - lo).abs().max(1e-9) * 0.08;
            hi += pad;
            if lo < 0.0 {
                lo -= pad;
            }
        }
        Axis { lo, hi, log }
    }

    /// Position in [0, 1].
    fn t(&self, x: f64) -> f64 {
        if self.log {
            (x.log10() - self.lo.log10()) / (self.hi.log10() - self.lo.log10())
        } else {
            (x - self.lo) / (self.hi - self.lo)
        }
    }

    fn ticks(&self) -> Vec<(f64, String)> {
        if self.log {
            let mut out = Vec::new();
            let mut v = self.lo;
            while v <= self.hi * 1.0001 {
                out.push((v, format_number(v)));
                v *= 10.0;
            }
            return out;
        }
        let span = self.hi - self.lo;
        let raw = span / 5.0;
        let p = 10f64.powf(raw.log10().floor());
        let step = [1.0, 2.0, 5.0, 10.0].iter().map(|m| m * p).find(|s| *s >= raw).unwrap_or(10.0 * p);
        let mut v = (self.lo / step).ceil() * step;
        let mut out = Vec::new();
        while v <= self.hi + 1e-9 * span {
            out.push((v, format_number(v)));
            v += step;
        }
        out
    }
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
        let s = format!("{v:.3}");
        s.trim_end_matches('0').to_string()
    }
}

fn rgba(c: [u8; 3]) -> Rgba<u8> {
    Rgba([c[0], c[1], c[2], 255])
}

fn text(img: &mut RgbaImage, x: i32, y: i32, size: f32, s: &str, color: [u8; 3]) {
    if let Some(f) = font() {
        draw_text_mut(img, rgba(color), x, y, PxScale::from(size), f, s);
    }
}

fn text_width(size: f32, s: &str) -> i32 {
    font().map_or(0, |f| text_size(PxScale::from(size), f, s).0 as i32)
}

fn thick_line(img: &mut RgbaImage, a: (f32, f32), b: (f32, f32), color: Rgba<u8>, width: i32, dashed: bool) {
    let len = ((b.0 - a.0).powi(2) + (b.1 - a.1).powi(2)).sqrt();
    let pieces = if dashed { (len / 6.0).ceil().max(1.0) as usize } else { 1 };
    for k in 0..pieces {
        if dashed && k % 2 == 1 {
            continue;
        }
        let (t0, t1) = (k as f32 / pieces as f32, ((k + 1) as f32 / pieces as f32).min(1.0));
        let p = (a.0 + (b.0 - a.0) * t0, a.1 + (b.1 - a.1) * t0);
        let q = (a.0 + (b.0 - a.0) * t1, a.1 + (b.1 - a.1) * t1);
        for d in -(width / 2)..=(width / 2) {
            let (dx, dy) = if (b.0 - a.0).abs() > (b.1 - a.1).abs() { (0.0, d as f32) } else { (d as f32, 0.0) };
            draw_line_segment_mut(img, (p.0 + dx, p.1 + dy), (q.0 + dx, q.1 + dy), color);
        }
    }
}

/// Draws one chart into `img` within the rectangle (x0, y0, w, h).
pub fn draw_chart(img: &mut RgbaImage, chart: &Chart, x0: i32, y0: i32, w: i32, h: i32) {
    // The legend takes a column right of the plot area, so it never hides data.
    let legend_w = chart.series.iter().map(|s| text_width(13.0, &s.label) + 40).max().unwrap_or(0);
    let (left, right, top, bottom) = (x0 + 78, x0 + w - 16 - legend_w, y0 + 58, y0 + h - 62);
    let xs = chart.series.iter().flat_map(|s| s.points.iter().map(|p| p.0)).chain(chart.x_ticks.iter().map(|t| t.0));
    let ys = chart.series.iter().flat_map(|s| {
        s.points
            .iter()
            .flat_map(|&(_, y, e)| [y, y + e.unwrap_or(0.0), if chart.y_log { y } else { y - e.unwrap_or(0.0) }])
    });
    let mut xa = Axis::fit(xs, chart.x_log);
    if !chart.x_ticks.is_empty() && !chart.x_log {
        let (lo, hi) =
            chart.x_ticks.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), t| (a.min(t.0), b.max(t.0)));
        xa = Axis { lo: lo - 0.5, hi: hi + 0.5, log: false };
    }
    let ya = Axis::fit(ys, chart.y_log);
    let px = |x: f64| left as f32 + (xa.t(x) as f32) * (right - left) as f32;
    let py = |y: f64| bottom as f32 - (ya.t(y) as f32) * (bottom - top) as f32;
    let grid = rgba([225, 225, 225]);
    let axis = rgba([60, 60, 60]);
    text(img, left, y0 + 6, 18.0, &chart.title, [20, 20, 20]);
    for (v, label) in ya.ticks() {
        let y = py(v);
        draw_line_segment_mut(img, (left as f32, y), (right as f32, y), grid);
        text(img, left - 8 - text_width(13.0, &label), y as i32 - 7, 13.0, &label, [60, 60, 60]);
    }
    let x_ticks = if chart.x_ticks.is_empty() { xa.ticks() } else { chart.x_ticks.clone() };
    for (v, label) in &x_ticks {
        let x = px(*v);
        draw_line_segment_mut(img, (x, top as f32), (x, bottom as f32), grid);
        text(img, x as i32 - text_width(13.0, label) / 2, bottom + 6, 13.0, label, [60, 60, 60]);
    }
    draw_line_segment_mut(img, (left as f32, bottom as f32), (right as f32, bottom as f32), axis);
    draw_line_segment_mut(img, (left as f32, top as f32), (left as f32, bottom as f32), axis);
    text(
        img,
        (left + right) / 2 - text_width(14.0, &chart.x_label) / 2,
        bottom + 26,
        14.0,
        &chart.x_label,
        [30, 30, 30],
    );
    // The y label runs along the top of the axis (no rotated text).
    text(img, x0 + 6, top - 24, 14.0, &chart.y_label, [30, 30, 30]);
    let inside = |y: f64| y.is_finite() && (!chart.y_log || y > 0.0);
    for s in &chart.series {
        let color = rgba(s.color);
        let pts: Vec<(f32, f32)> = s.points.iter().filter(|p| inside(p.1)).map(|p| (px(p.0), py(p.1))).collect();
        for w in pts.windows(2) {
            thick_line(img, w[0], w[1], color, 2, s.dashed);
        }
        for &(x, y, e) in s.points.iter().filter(|p| inside(p.1)) {
            if let Some(e) = e.filter(|e| *e > 0.0) {
                let lo = if chart.y_log { (y - e).max(ya.lo) } else { y - e };
                let (cx, a, b) = (px(x), py(lo), py(y + e));
                draw_line_segment_mut(img, (cx, a), (cx, b), color);
                draw_line_segment_mut(img, (cx - 4.0, a), (cx + 4.0, a), color);
                draw_line_segment_mut(img, (cx - 4.0, b), (cx + 4.0, b), color);
            }
            if s.markers {
                draw_filled_circle_mut(img, (px(x) as i32, py(y) as i32), 4, color);
            }
        }
    }
    // Legend, in its column.
    let mut ly = top + 6;
    for s in &chart.series {
        let lw = text_width(13.0, &s.label);
        let lx = right + 12;
        draw_filled_rect_mut(img, Rect::at(lx - 4, ly - 2).of_size((lw + 36) as u32, 18), rgba([255, 255, 255]));
        thick_line(img, (lx as f32, ly as f32 + 7.0), (lx as f32 + 22.0, ly as f32 + 7.0), rgba(s.color), 2, s.dashed);
        text(img, lx + 28, ly, 13.0, &s.label, [30, 30, 30]);
        ly += 18;
    }
}

/// Draws charts in a grid of `columns`, each panel w × h pixels, on a white background.
pub fn draw_panels(charts: &[Chart], columns: usize, w: u32, h: u32) -> RgbaImage {
    let rows = charts.len().div_ceil(columns.max(1)) as u32;
    let mut img = RgbaImage::from_pixel(w * columns as u32, h * rows.max(1), Rgba([255, 255, 255, 255]));
    for (i, c) in charts.iter().enumerate() {
        let (col, row) = ((i % columns) as i32, (i / columns) as i32);
        draw_chart(&mut img, c, col * w as i32, row * h as i32, w as i32, h as i32);
    }
    img
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axes_cover_the_data_and_draw_the_series() {
        let chart = Chart {
            title: "t".into(),
            y_log: true,
            series: vec![Series {
                label: "a".into(),
                points: vec![(1.0, 0.05, Some(0.01)), (2.0, 30.0, None), (3.0, f64::NAN, None)],
                color: PALETTE[1],
                dashed: false,
                markers: true,
            }],
            ..Default::default()
        };
        let img = draw_panels(&[chart], 1, 400, 300);
        assert_eq!(img.dimensions(), (400, 300));
        // The series colour appears (markers and the line were drawn).
        let c = PALETTE[1];
        let n = img.pixels().filter(|p| p.0[..3] == c).count();
        assert!(n > 50, "{n} series pixels");
        let a = Axis::fit([0.05, 30.0].into_iter(), true);
        assert!(a.lo <= 0.05 && a.hi >= 30.0);
        assert!(Axis::fit([2.0, 7.0].into_iter(), false).ticks().len() >= 3);
    }
}
