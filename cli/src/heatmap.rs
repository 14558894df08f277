//! Error heatmaps: the per-pixel display-position error of both eyes (left on top), colour-mapped
//! from 0 to a scale maximum, with the scale drawn under the images (a colour bar with ticks
//! labelled in pixels, text by plotters). Background and unseen pixels are dark grey.

/// A perceptually ordered colour map (dark blue → teal → yellow → red), t in [0, 1].
pub fn colormap(t: f32) -> [u8; 3] {
    const STOPS: [[f32; 3]; 5] =
        [[0.05, 0.05, 0.35], [0.1, 0.45, 0.75], [0.2, 0.75, 0.45], [0.95, 0.85, 0.2], [0.85, 0.1, 0.1]];
    let t = t.clamp(0.0, 1.0) * (STOPS.len() - 1) as f32;
    let i = (t.floor() as usize).min(STOPS.len() - 2);
    let f = t - i as f32;
    let c: Vec<u8> =
        (0..3).map(|k| ((STOPS[i][k] + (STOPS[i + 1][k] - STOPS[i][k]) * f) * 255.0).round() as u8).collect();
    [c[0], c[1], c[2]]
}

/// An RGB canvas.
struct Canvas {
    width: u32,
    height: u32,
    rgb: Vec<u8>,
}

impl Canvas {
    fn set(&mut self, x: u32, y: u32, c: [u8; 3]) {
        if x < self.width && y < self.height {
            let i = 3 * (y * self.width + x) as usize;
            self.rgb[i..i + 3].copy_from_slice(&c);
        }
    }
}

/// A round scale maximum at or above `max` (1, 2 or 5 × 10^k).
pub fn nice_max(max: f32) -> f32 {
    if !(max > 0.0) {
        return 1.0;
    }
    let p = 10f32.powf(max.log10().floor());
    [1.0, 2.0, 5.0, 10.0].iter().map(|m| m * p).find(|&v| v >= max).unwrap_or(10.0 * p)
}

/// The heatmap image (RGBA8): both eyes' errors stacked, then the scale.
pub fn heatmap(errors: &[Vec<f32>; 2], width: u32, height: u32, scale_max: f32) -> (u32, u32, Vec<u8>) {
    let text_scale = (width / 400).clamp(1, 4);
    let bar_h = 12 * text_scale;
    let total_h = 2 * height + bar_h + 10 * text_scale;
    let mut c = Canvas { width, height: total_h, rgb: [20u8, 20, 20].repeat((width * total_h) as usize) };
    for (k, err) in errors.iter().enumerate() {
        for y in 0..height {
            for x in 0..width {
                let e = err[(y * width + x) as usize];
                let color = if e >= 0.0 { colormap(e / scale_max) } else { [40, 40, 40] };
                c.set(x, k as u32 * height + y, color);
            }
        }
    }
    let top = 2 * height + 2 * text_scale;
    let (x0, x1) = (width / 20, width - width / 20);
    for x in x0..x1 {
        let color = colormap((x - x0) as f32 / (x1 - x0) as f32);
        for y in top..top + bar_h / 2 {
            c.set(x, y, color);
        }
    }
    for i in 0..=4 {
        let x = x0 + (x1 - x0) * i / 4;
        let value = scale_max * i as f32 / 4.0;
        let label = if scale_max >= 4.0 { format!("{value:.0}") } else { format!("{value:.2}") };
        let label = if i == 4 { format!("{label}px") } else { label };
        for y in top..top + bar_h / 2 + text_scale {
            c.set(x, y, [255; 3]);
        }
        let size = 6 * text_scale + 2;
        let label_w = crate::plot::label_width(size, &label);
        let tx = x.saturating_sub(label_w / 2).min(width.saturating_sub(label_w));
        let ty = top + bar_h / 2 + text_scale;
        crate::plot::label(&mut c.rgb, width, total_h, tx as i32, ty as i32, size, &label);
    }
    (width, total_h, c.rgb.chunks(3).flat_map(|p| [p[0], p[1], p[2], 255]).collect())
}
