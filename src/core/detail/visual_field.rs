//! The human visual field as seeds 000 (eq. 1–8) and 001 (§2.1–2.2) model it: where a direction
//! falls relative to a gaze (central field, peripheral field, outside), and the level of detail
//! it deserves there.
//!
//! A gaze is the viewer's eye point with a direction E_f, its right E_r and up E_u. For a unit
//! direction D: d_f = E_f·D, d_r = E_r·D, d_u = E_u·D;
//! m_α = acos(d_f/√(d_f²+d_r²)) ∈ [0, π] (horizontal angle), m_β = ±acos(|d_f|/√(d_f²+d_u²)) with
//! the sign of d_u (vertical angle), l = √(m_α²+m_β²).
//! The visual field's boundary along that direction, L (eq. 7), is where the ray from the origin
//! through (m_α, m_β) meets the ellipse of semi-axes 5π/9 horizontally, π/3 upwards and 7π/18
//! downwards. Central field: l ≤ π/6; peripheral: π/6 < l ≤ L; outside: l > L.
//! Level (eq. 8): 1 central, (L − l)/(L − π/6) peripheral, 0 outside.

use std::f32::consts::PI;

use glam::Vec3;

/// Radius of the central field, radians (30°).
pub const CENTRAL_RADIUS: f32 = PI / 6.0;
/// Semi-axes of the visual field's boundary: sideways, upwards, downwards (100°, 60°, 70°).
pub const FIELD_SIDEWAYS: f32 = 5.0 * PI / 9.0;
pub const FIELD_UP: f32 = PI / 3.0;
pub const FIELD_DOWN: f32 = 7.0 * PI / 18.0;

/// Where a direction falls.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Field {
    Central,
    Peripheral,
    Outside,
}

/// A gaze in the viewer frame (+y up, straight ahead −z).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gaze {
    pub forward: Vec3,
    pub right: Vec3,
    pub up: Vec3,
}

impl Default for Gaze {
    fn default() -> Self {
        Gaze::new(0.0, 0.0)
    }
}

/// A tracked viewer's gaze over time (`--gaze-path FILE`, the seeds' tracked viewer): rows of
/// time (s), yaw and pitch (degrees, as `--gaze`), blended linearly (`core::scenes::timeline`).
#[derive(Clone, Debug, PartialEq)]
pub struct GazePath(pub crate::core::scenes::timeline::Timeline);

impl GazePath {
    /// Reads a CSV of `time,yaw,pitch` rows; one line naming the file and row otherwise.
    pub fn read(path: &std::path::Path) -> crate::error::Result<GazePath> {
        let check = |v: &[f32]| (v[1].abs() > 89.0).then(|| "pitch within ±89".to_string());
        crate::core::scenes::timeline::Timeline::read(path, "gaze_path", (2, 2), "time,yaw,pitch", check).map(GazePath)
    }

    /// The gaze at time t.
    pub fn at(&self, t: f32) -> Gaze {
        let v = self.0.at(t);
        Gaze::new(v[0], v[1])
    }
}

/// A direction's place in the visual field.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FieldPosition {
    /// m_α ∈ [0, π], m_β ∈ [−π/2, π/2], l = √(m_α² + m_β²), radians.
    pub m_alpha: f32,
    pub m_beta: f32,
    pub l: f32,
    /// L: the boundary of the visual field along this direction (eq. 7).
    pub boundary: f32,
}

impl Gaze {
    /// A gaze turned `yaw_deg` to the left and `pitch_deg` up from straight ahead (pitch is
    /// kept within ±89°, where right and up stay defined).
    pub fn new(yaw_deg: f32, pitch_deg: f32) -> Gaze {
        let (yaw, pitch) = (yaw_deg.to_radians(), pitch_deg.clamp(-89.0, 89.0).to_radians());
        let forward = Vec3::new(-yaw.sin() * pitch.cos(), pitch.sin(), -yaw.cos() * pitch.cos());
        let right = forward.cross(Vec3::Y).normalize();
        Gaze { forward, right, up: right.cross(forward) }
    }

    /// Where direction `d` (any length > 0) falls (eq. 1–7).
    pub fn position(&self, d: Vec3) -> FieldPosition {
        let d = d.normalize();
        let (df, dr, du) = (self.forward.dot(d), self.right.dot(d), self.up.dot(d));
        let horizontal = (df * df + dr * dr).sqrt();
        // Straight up or down from the gaze's horizontal plane the horizontal angle is 0.
        let m_alpha = if horizontal > 1e-9 { (df / horizontal).clamp(-1.0, 1.0).acos() } else { 0.0 };
        let vertical = (df * df + du * du).sqrt();
        let m_beta = if vertical > 1e-9 { (df.abs() / vertical).clamp(-1.0, 1.0).acos().copysign(du) } else { 0.0 };
        let l = (m_alpha * m_alpha + m_beta * m_beta).sqrt();
        FieldPosition { m_alpha, m_beta, l, boundary: boundary(m_alpha, m_beta) }
    }
}

/// L (eq. 7): the distance from the origin to the field's boundary ellipse along (m_α, m_β).
pub fn boundary(m_alpha: f32, m_beta: f32) -> f32 {
    let l = (m_alpha * m_alpha + m_beta * m_beta).sqrt();
    if l == 0.0 {
        return FIELD_SIDEWAYS.min(FIELD_UP).min(FIELD_DOWN);
    }
    let b = if m_beta >= 0.0 { FIELD_UP } else { FIELD_DOWN };
    let (c, s) = (m_alpha / l, m_beta / l);
    1.0 / ((c / FIELD_SIDEWAYS).powi(2) + (s / b).powi(2)).sqrt()
}

impl FieldPosition {
    pub fn field(&self) -> Field {
        if self.l <= CENTRAL_RADIUS {
            Field::Central
        } else if self.l <= self.boundary {
            Field::Peripheral
        } else {
            Field::Outside
        }
    }

    /// The level of detail (eq. 8): 1 central, falling linearly to 0 at the boundary, 0 outside.
    pub fn level(&self) -> f32 {
        match self.field() {
            Field::Central => 1.0,
            Field::Peripheral => (self.boundary - self.l) / (self.boundary - CENTRAL_RADIUS),
            Field::Outside => 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(gaze: &Gaze, yaw_deg: f32, pitch_deg: f32) -> FieldPosition {
        // The direction yaw_deg left and pitch_deg up of straight ahead, in the viewer frame.
        let (y, p) = (yaw_deg.to_radians(), pitch_deg.to_radians());
        gaze.position(Vec3::new(-y.sin() * p.cos(), p.sin(), -y.cos() * p.cos()))
    }

    #[test]
    fn known_directions_fall_where_the_model_says() {
        let g = Gaze::default();
        let ahead = at(&g, 0.0, 0.0);
        assert_eq!((ahead.l, ahead.field(), ahead.level()), (0.0, Field::Central, 1.0));
        // 30° sideways or up is the edge of the central field.
        for (yaw, pitch) in [(29.9, 0.0), (-29.9, 0.0), (0.0, 29.9), (0.0, -29.9)] {
            assert_eq!(at(&g, yaw, pitch).field(), Field::Central, "{yaw} {pitch}");
        }
        for (yaw, pitch) in [(30.1, 0.0), (0.0, 30.1), (0.0, -30.1)] {
            assert_eq!(at(&g, yaw, pitch).field(), Field::Peripheral, "{yaw} {pitch}");
        }
        // The boundary: 100° sideways, 60° up, 70° down.
        for (yaw, pitch, edge) in [(100.0, 0.0, 100.0), (-100.0, 0.0, 100.0), (0.0, 60.0, 60.0), (0.0, -70.0, 70.0)] {
            let inside = at(&g, yaw * 0.99, pitch * 0.99);
            let outside = at(&g, yaw * 1.01, pitch * 1.01);
            assert_eq!(inside.field(), Field::Peripheral, "{yaw} {pitch}");
            assert_eq!(outside.field(), Field::Outside, "{yaw} {pitch}");
            assert!((inside.boundary.to_degrees() - edge).abs() < 1e-3, "{}", inside.boundary.to_degrees());
        }
        let behind = at(&g, 180.0, 0.0);
        assert!((behind.m_alpha - PI).abs() < 1e-6 && behind.m_beta == 0.0);
        assert_eq!((behind.field(), behind.level()), (Field::Outside, 0.0));
        // 65° sideways: peripheral, level (100 − 65)/(100 − 30) = 0.5.
        let side = at(&g, 65.0, 0.0);
        assert!((side.level() - 0.5).abs() < 1e-5, "{}", side.level());
        // On a diagonal the boundary lies on the ellipse: (m_α/100°)² + (m_β/60°)² = 1.
        let d = at(&g, 50.0, 40.0);
        let (a, b) = (d.m_alpha * d.boundary / d.l, d.m_beta * d.boundary / d.l);
        assert!(((a / FIELD_SIDEWAYS).powi(2) + (b / FIELD_UP).powi(2) - 1.0).abs() < 1e-5);
    }

    #[test]
    fn the_field_turns_with_the_gaze() {
        // Gazing 90° left and 20° up: that direction is the centre; straight ahead is 90° off.
        let g = Gaze::new(90.0, 20.0);
        assert!(at(&g, 90.0, 20.0).l < 1e-3);
        assert!((g.forward.dot(g.right)).abs() < 1e-6 && (g.forward.dot(g.up)).abs() < 1e-6);
        assert!(g.up.y > 0.0 && g.right.z < 0.0, "{g:?}");
        let ahead = at(&g, 0.0, 0.0);
        assert!(ahead.m_alpha > 1.5, "{ahead:?}");
        // m_β keeps the sign of the vertical offset, m_α does not.
        let below = at(&Gaze::default(), 10.0, -20.0);
        let above = at(&Gaze::default(), -10.0, 20.0);
        assert!(below.m_beta < 0.0 && above.m_beta > 0.0 && (below.m_alpha - above.m_alpha).abs() < 1e-6);
    }
}
