//! CPU twin of `shaders/shared/subdivide_axis.wgsl`.
//!
//! The vertical axis (see the module doc of `cpu::subdivide`). Triangles near the axis, or
//! large next to their distance from it, are cut into **parts**: their polygon in each of the
//! four quadrants around the axis (cut by the planes x = 0 and z = 0), for the adaptive rules
//! (and every method on the cylinder: [`band_limit`]) cut further into **bands** by the diamonds |x| + |z| = c_k, c_k = ρ·√2^k ([`band_bound`]),
//! minus the innermost diamond (half-diagonal ρ = [`axis_clearance`]), each fan-triangulated.
//! The parts are what the pre-split and the lattice subdivide.
//!
//! **Which cuts a frame makes.** A first pass over every on-screen triangle of the scene
//! (`active_cuts`, before `plan`) collects the cuts the frame makes ([`AxisCuts`]): a triangle
//! that reaches the first diamond, or whose diamond distances span more than `WIDE_RATIO`,
//! switches on the quadrant cuts and the square, and (adaptive) every diamond that crosses it
//! ([`triangle_cuts`]); it also marks its three edges (by the scene's shared-edge numbers,
//! `core::scenes::shared_edges`). Such a triangle, and any triangle that has one of those edges (a wall
//! beside a floor), is then cut at the quadrant planes and the active diamonds it crosses
//! ([`polygons`]); a second pass (`ring_cuts`) marks the edges of the latter too. Any other
//! triangle is small next to its distance from the axis and needs no cut for itself: it is cut
//! only at the points where its marked edges (those it shares with a cut triangle) cross the
//! cuts ([`edge_crossings`], [`edge_split_parts`]), so that it meets its cut neighbours there; a
//! triangle with no marked edge is its own single part. A scene with no triangle that asks is
//! not cut at all; in a room, the floor and ceiling near the axis and two rings of their
//! neighbours are. (A triangle that straddles x = 0, z = 0 or an active diamond but needs none
//! of it stays whole; the second ring keeps large walls beside a floor in bands, which are
//! fewer triangles than fanning them at their marked edges: see docs/results.md.)
//!
//! **Why bands.** The projection stretches ∝ 1/r (v = R_T·y/r, and θ turns fast near the axis),
//! so eq. 5's equal parts of an edge that runs from near the axis outwards would be far longer on
//! screen at the inner end than at the outer. Within a band r varies by at most a factor 2, so
//! equal parts stay about equally long; a ceiling just above the eyes is split finely where it
//! shows large and coarsely where it is far, and off-screen bands (a floor near the axis) are
//! culled whole.
//!
//! **Why this is watertight.** Every point where a part's boundary meets another part's is
//! computed from one edge alone, the same way in every triangle that has that edge:
//! - where an input edge crosses x = 0 or z = 0: from its canonically ordered endpoints, and
//!   the crossed coordinate is then set to exactly 0;
//! - where a sub-segment of an input edge (between such crossings) meets a diamond: likewise
//!   (the two sides of a diamond use the same distance, negated, so the same point);
//! - where a cut line (inside a triangle, on x = 0 or z = 0) meets a diamond: both quadrants
//!   beside it see the same segment, whose crossed coordinate is exactly 0, so the diamond's
//!   distance `sx·x + sz·z − c` is the same number in both.
//!
//! An edge is cut either in both its triangles or in neither: every edge of a cut triangle is
//! marked (by `active_cuts` or `ring_cuts`), and its neighbour, cut or not, then cuts it. A
//! neighbour that is not cut replays on the edge alone the clips [`polygons`] makes, in the same
//! order ([`edge_crossings`]), so its points are the same to the last bit; inside, it is fanned
//! from a corner or its centroid.
//!
//! Vertices within `SNAP` (relative) of a cutting plane are moved onto it first, so that the
//! CPU and the GPU, whose matrix products differ in the last bits, take the same side.
//!
//! **What is removed.** Only the diamond |x| + |z| < ρ around the axis, whose points have
//! r < ρ ≤ d_e: no eye sees them. Points between it and the eye circle (r < d_e) stay and are
//! drawn with the eye offset of the eye circle (`Projection::eye_shift` clamps), far above or
//! below the image in the exact vertical model and just beyond the circle's image in the paper
//! model, so that a ceiling close above the viewer has no hole in either.
//!
//! **Cost.** Only the triangles that ask for cuts and two rings of their neighbours are cut, and
//! only when the frame has active cuts at all; all others are their own single part.

use glam::Vec3;

use super::spacing::weighted;
use super::Node;
use crate::encoding::constants::{BAND_LIMIT, BAND_RATIO, MAX_DIAMONDS, SNAP, WIDE_RATIO};
pub use crate::encoding::subdivide::{axis_clearance, AxisCuts};

/// The quadrants (sign of x, sign of z), in the order the twin and the WGSL number parts.
pub const QUADRANTS: [(f32, f32); 4] = [(1.0, -1.0), (1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0)];

/// Moves a vertex within `SNAP` (relative to |x| + |z|) of the plane x = 0 or z = 0 onto it.
pub fn snap_to_cut_planes(p: Vec3) -> Vec3 {
    let scale = SNAP * (p.x.abs() + p.z.abs());
    Vec3::new(if p.x.abs() <= scale { 0.0 } else { p.x }, p.y, if p.z.abs() <= scale { 0.0 } else { p.z })
}

/// A half-plane a part is clipped by.
#[derive(Clone, Copy, Debug)]
enum Cut {
    /// s·x ≥ 0 (the crossed coordinate of a crossing point is set to 0).
    X(f32),
    /// s·z ≥ 0.
    Z(f32),
    /// side·(sx·x + sz·z − c) ≥ 0: beyond (side 1) or within (side −1) the diamond |x| + |z| = c
    /// of the quadrant (sx, sz).
    Chord(f32, f32, f32, f32),
}

impl Cut {
    fn distance(self, p: Vec3) -> f32 {
        match self {
            Cut::X(s) => s * p.x,
            Cut::Z(s) => s * p.z,
            Cut::Chord(sx, sz, c, side) => {
                let d = sx * p.x + sz * p.z - c;
                if d.abs() <= SNAP * (p.x.abs() + p.z.abs() + c) {
                    0.0
                } else {
                    side * d
                }
            }
        }
    }

    /// The crossing of segment lo→hi (canonically ordered) with distances dl, dh of opposite signs.
    fn crossing(self, lo: Node, hi: Node, dl: f32, dh: f32) -> Node {
        let t = dl / (dl - dh);
        let mut n =
            Node { position: lo.position + (hi.position - lo.position) * t, bary: lo.bary + (hi.bary - lo.bary) * t };
        let scale = SNAP * (lo.position.x.abs() + lo.position.z.abs() + hi.position.x.abs() + hi.position.z.abs());
        match self {
            Cut::X(_) => {
                n.position.x = 0.0;
                if n.position.z.abs() <= scale {
                    n.position.z = 0.0;
                }
            }
            Cut::Z(_) => {
                n.position.z = 0.0;
                if n.position.x.abs() <= scale {
                    n.position.x = 0.0;
                }
            }
            Cut::Chord(..) => {}
        }
        n
    }
}

/// A convex polygon of at most 7 vertices (a triangle clipped by four half-planes).
#[derive(Clone, Copy, Debug)]
struct Polygon {
    nodes: [Node; 7],
    count: usize,
}

impl Polygon {
    fn push(&mut self, n: Node) {
        if self.count == 0 || self.nodes[self.count - 1].position != n.position {
            self.nodes[self.count] = n;
            self.count += 1;
        }
    }

    /// Sutherland–Hodgman clip against one half-plane; crossing points come from the
    /// canonically ordered edge, so a neighbour that clips the same edge gets the same point.
    fn clip(&self, cut: Cut) -> Polygon {
        let mut out = Polygon { nodes: [self.nodes[0]; 7], count: 0 };
        for i in 0..self.count {
            let cur = self.nodes[i];
            let next = self.nodes[(i + 1) % self.count];
            let (d0, d1) = (cut.distance(cur.position), cut.distance(next.position));
            if d0 >= 0.0 {
                out.push(cur);
            }
            if (d0 >= 0.0) != (d1 >= 0.0) && d0 != 0.0 && d1 != 0.0 {
                let (lo, hi, dl, dh) = if super::lex_less(next.position, cur.position) {
                    (next, cur, d1, d0)
                } else {
                    (cur, next, d0, d1)
                };
                out.push(cut.crossing(lo, hi, dl, dh));
            }
        }
        if out.count > 1 && out.nodes[out.count - 1].position == out.nodes[0].position {
            out.count -= 1;
        }
        if out.count < 3 {
            out.count = 0;
        }
        out
    }

    /// This polygon, leaving an empty one.
    fn take(&mut self) -> Polygon {
        let whole = *self;
        self.count = 0;
        whole
    }

    /// Whether every corner is on the far side of the cut (the clip would be empty), or none is
    /// (the clip would change nothing; the opposite clip would be empty).
    fn all_beyond(&self, cut: Cut) -> (bool, bool) {
        let d = self.nodes[..self.count].iter().map(|n| cut.distance(n.position));
        let (mut beyond, mut within) = (true, true);
        for d in d {
            beyond &= d < 0.0;
            within &= d >= 0.0;
        }
        (beyond, within)
    }
}

/// The diamond |x| + |z| = c_k, c_k = ρ·√2^k (k ≥ 0; c_0 = ρ bounds the square around the
/// axis): within the band between two consecutive diamonds r varies by at most 2, so equal parts
/// of an edge stay about equally long on screen (the projection stretches ∝ 1/r). Computed
/// exactly as the WGSL does: ρ or ρ·√2 (one rounding) times 2^(k/2).
pub fn band_bound(rho: f32, k: u32) -> f32 {
    let base = if k % 2 == 0 { rho } else { rho * BAND_RATIO };
    base * 2f32.powi((k / 2) as i32)
}

/// The smallest and largest diamond distance |x| + |z| of a triangle's points: the largest at
/// a corner; the smallest 0 where the triangle's footprint (its projection along y) holds the
/// axis, else on an edge, at an end or where the edge crosses x = 0 or z = 0 (|x| + |z| is
/// linear between those). `diamond_range` in the WGSL.
pub fn diamond_range(p: [Vec3; 3]) -> (f32, f32) {
    let d = p.map(|q| q.x.abs() + q.z.abs());
    let hi = d[0].max(d[1]).max(d[2]);
    // Which side of each footprint edge the axis lies on.
    let side = |a: Vec3, b: Vec3| (b.z - a.z) * a.x - (b.x - a.x) * a.z;
    let s = [side(p[0], p[1]), side(p[1], p[2]), side(p[2], p[0])];
    if s.iter().all(|&x| x >= 0.0) || s.iter().all(|&x| x <= 0.0) {
        return (0.0, hi);
    }
    let mut lo = d[0].min(d[1]).min(d[2]);
    for e in 0..3 {
        let (a, b) = (p[e], p[(e + 1) % 3]);
        if (a.x < 0.0) != (b.x < 0.0) && a.x != 0.0 && b.x != 0.0 {
            lo = lo.min((a.z + (b.z - a.z) * (a.x / (a.x - b.x))).abs());
        }
        if (a.z < 0.0) != (b.z < 0.0) && a.z != 0.0 && b.z != 0.0 {
            lo = lo.min((a.x + (b.x - a.x) * (a.z / (a.z - b.z))).abs());
        }
    }
    (lo, hi)
}

/// The cuts one on-screen triangle asks for. A triangle that reaches the first diamond c_1, or
/// whose diamond distances span more than `WIDE_RATIO` (d_max > `WIDE_RATIO`·d_min), asks for
/// the quadrant cuts and the square (bit 0) and, below `limit` ([`band_limit`]), for every
/// diamond that crosses it. Others ask for nothing: r changes little across them, and eq. 5
/// with the stretch rule splits them well (see the module doc).
pub fn triangle_cuts(p: [Vec3; 3], rho: f32, limit: f32) -> AxisCuts {
    let (lo, hi) = diamond_range(p);
    if !(lo < band_bound(rho, 1) || hi > WIDE_RATIO * lo) {
        return 0;
    }
    let mut cuts = 1;
    for k in 1..MAX_DIAMONDS {
        let c = band_bound(rho, k);
        if c >= limit || c >= hi {
            break;
        }
        if lo < c {
            cuts |= 1 << k;
        }
    }
    cuts
}

/// The largest k < `MAX_DIAMONDS` with c_k ≤ d (0 if none): an estimate from the logarithm,
/// then exact steps. `band_of` in the WGSL.
fn band_of(rho: f32, d: f32) -> u32 {
    let mut k = (2.0 * (d / rho).max(1.0).log2()).min((MAX_DIAMONDS - 1) as f32) as u32;
    while k > 0 && band_bound(rho, k) > d {
        k -= 1;
    }
    while k + 1 < MAX_DIAMONDS && band_bound(rho, k + 1) <= d {
        k += 1;
    }
    k
}

/// The next active diamond after k, or `MAX_DIAMONDS` if none. `next_cut` in the WGSL.
fn next_cut(cuts: AxisCuts, k: u32) -> u32 {
    let above = if k + 1 >= MAX_DIAMONDS { 0 } else { cuts & (u64::MAX << (k + 1)) };
    if above == 0 {
        MAX_DIAMONDS
    } else {
        above.trailing_zeros()
    }
}

/// The active diamond at or below distance d: the largest active k with c_k ≤ d (k = 0, the
/// square, always counts). `zone_of` in the WGSL.
fn zone_of(cuts: AxisCuts, rho: f32, d: f32) -> u32 {
    let mut k = band_of(rho, d);
    while k > 0 && cuts & (1 << k) == 0 {
        k -= 1;
    }
    k
}

/// Whether a triangle lies strictly inside quadrant (sx, sz) and between two consecutive active
/// diamonds: then it is its own single part (the clips would change nothing, see [`polygons`]).
/// `single_band` in the WGSL.
fn single_band(p: [Vec3; 3], (sx, sz): (f32, f32), rho: f32, cuts: AxisCuts) -> bool {
    if !p.iter().all(|q| sx * q.x > 0.0 && sz * q.z > 0.0) {
        return false;
    }
    let d_min = p.iter().map(|q| sx * q.x + sz * q.z).fold(f32::INFINITY, f32::min);
    let k = zone_of(cuts, rho, d_min);
    let lower = Cut::Chord(sx, sz, band_bound(rho, k), 1.0);
    let next = next_cut(cuts, k);
    let upper = (next < MAX_DIAMONDS).then(|| Cut::Chord(sx, sz, band_bound(rho, next), -1.0));
    p.iter().all(|&q| lower.distance(q) > 0.0 && upper.is_none_or(|u| u.distance(q) > 0.0))
}

/// Where diamonds stop: `BAND_LIMIT`·R_T for the adaptive rules, and on the cylinder for every
/// method: `vertex` and `fixed:N` split no edge by its projected length, but the cylinder's
/// v = R_T·y/√(r² − d_e²) grows without bound towards the eye circle, and a part that reaches
/// from there to far out projects, in straight lines, as a polygon that is no longer simple (a
/// ceiling's corner above a tracked head, fanned over points thousands of pixels above the
/// image); within a band r varies by at most a factor 2 and the fans stay simple. The sphere's
/// latitude is bounded: there they cut only the square (0).
pub fn band_limit(method: u32, projection: &crate::core::panoramas::projection::Projection) -> f32 {
    if crate::core::settings::SplitRule::is_adaptive(method) || !projection.panorama.is_sphere() {
        BAND_LIMIT * projection.screen_radius
    } else {
        0.0
    }
}

/// The active diamonds' bounds, innermost first.
fn active_bounds(rho: f32, cuts: AxisCuts) -> impl Iterator<Item = f32> {
    (1..MAX_DIAMONDS).filter(move |k| cuts & (1 << k) != 0).map(move |k| band_bound(rho, k))
}

/// Clips segment (p, q) to the side `cut` ≥ 0 as [`Polygon::clip`] clips a polygon's edge
/// (the crossing from the canonically ordered pair), recording the crossing; `None` when
/// nothing of it (or one point) is left.
fn clip_segment((p, q): (Node, Node), cut: Cut, crossings: &mut Vec<Node>) -> Option<(Node, Node)> {
    let (dp, dq) = (cut.distance(p.position), cut.distance(q.position));
    if (dp >= 0.0) != (dq >= 0.0) && dp != 0.0 && dq != 0.0 {
        let (lo, hi, dl, dh) = if super::lex_less(q.position, p.position) { (q, p, dq, dp) } else { (p, q, dp, dq) };
        let x = cut.crossing(lo, hi, dl, dh);
        crossings.push(x);
        return Some(if dp >= 0.0 { (p, x) } else { (x, q) });
    }
    (dp >= 0.0 && dq >= 0.0).then_some((p, q))
}

/// The points where [`polygons`] cuts the edge a → b of a triangle under `cuts` (its ends
/// excluded), in order from a: the same clips in the same order on the edge alone, quadrant by
/// quadrant and band by band, so the same points to the last bit as a triangle that is cut
/// makes on it. `edge_crossings` in the WGSL.
pub fn edge_crossings(a: Node, b: Node, rho: f32, cuts: AxisCuts) -> Vec<Node> {
    let mut found = Vec::new();
    for (sx, sz) in QUADRANTS {
        let mut segment = Some((a, b));
        for cut in [Cut::X(sx), Cut::Z(sz), Cut::Chord(sx, sz, rho, 1.0)]
            .into_iter()
            .chain(active_bounds(rho, cuts).map(|c| Cut::Chord(sx, sz, c, 1.0)))
        {
            let Some(s) = segment else { break };
            segment = clip_segment(s, cut, &mut found);
        }
    }
    let along = |n: &Node| (n.position - a.position).dot(b.position - a.position);
    let mut out: Vec<Node> = Vec::with_capacity(found.len());
    for n in found {
        if n.position != a.position && n.position != b.position && out.iter().all(|o| o.position != n.position) {
            out.push(n);
        }
    }
    out.sort_by(|m, n| along(m).total_cmp(&along(n)));
    out
}

/// The parts of a triangle that is not cut by all cuts (corners `p`, snapped) whose edges marked
/// in `shared` are cut triangles' edges too: cut only at those edges' [`edge_crossings`], so
/// that its neighbours' points are its corners too. With crossings on one edge, the fan from the
/// opposite corner; on more, the fan from the centroid over the whole boundary; with none, the
/// triangle. `plan_edge_split` in the WGSL.
pub fn edge_split_parts(p: [Vec3; 3], shared: [bool; 3], rho: f32, cuts: AxisCuts) -> Vec<[Node; 3]> {
    let bary = [Vec3::X, Vec3::Y, Vec3::Z];
    let corner = |i: usize| Node { position: p[i], bary: bary[i] };
    let crossings: [Vec<Node>; 3] =
        [0, 1, 2].map(|e| if shared[e] { edge_crossings(corner(e), corner((e + 1) % 3), rho, cuts) } else { vec![] });
    let crossed: Vec<usize> = (0..3).filter(|&e| !crossings[e].is_empty()).collect();
    match crossed[..] {
        [] => vec![[corner(0), corner(1), corner(2)]],
        [e] => {
            let chain: Vec<Node> =
                std::iter::once(corner(e)).chain(crossings[e].iter().copied()).chain([corner((e + 1) % 3)]).collect();
            chain.windows(2).map(|w| [corner((e + 2) % 3), w[0], w[1]]).collect()
        }
        _ => {
            let centre = weighted(&[corner(0), corner(1), corner(2)], Vec3::splat(1.0 / 3.0));
            let boundary: Vec<Node> =
                (0..3).flat_map(|e| std::iter::once(corner(e)).chain(crossings[e].iter().copied())).collect();
            (0..boundary.len()).map(|i| [centre, boundary[i], boundary[(i + 1) % boundary.len()]]).collect()
        }
    }
}

/// The fan triangulation of a band's polygon from its first corner: its parts.
pub fn fan(poly: &[Node]) -> impl Iterator<Item = [Node; 3]> + '_ {
    (1..poly.len().saturating_sub(1)).map(move |i| [poly[0], poly[i], poly[i + 1]])
}

/// The polygons of a triangle (corners in the viewer frame, already snapped) under the frame's
/// `cuts`, each band's in its order (3 to 7 corners; their [`fan`]s are the parts); corners carry
/// barycentric weights in the triangle. Numbered quadrant by quadrant ([`QUADRANTS`]), band by
/// band outwards (the active diamonds). With no cut active, the triangle is its own polygon.
pub fn polygons(p: [Vec3; 3], rho: f32, cuts: AxisCuts) -> Vec<Vec<Node>> {
    // Most triangles: one quadrant, one band, one part (what the clips would give, faster).
    if one_part(p, rho, cuts) {
        return vec![[0, 1, 2].map(|i| Node { position: p[i], bary: Vec3::AXES[i] }).to_vec()];
    }
    (0..QUADRANTS.len()).flat_map(|q| quadrant_polygons(p, rho, cuts, q)).collect()
}

/// Whether a triangle is its own single polygon under `cuts`: none active, or it lies in one
/// quadrant and one band ([`single_band`]). `single_part` in the WGSL.
pub fn one_part(p: [Vec3; 3], rho: f32, cuts: AxisCuts) -> bool {
    cuts == 0 || QUADRANTS.iter().any(|&q| single_band(p, q, rho, cuts))
}

/// The polygons of [`polygons`] in quadrant `q` of [`QUADRANTS`], band by band outwards
/// (`plan_quadrant` in the WGSL).
pub fn quadrant_polygons(p: [Vec3; 3], rho: f32, cuts: AxisCuts, q: usize) -> Vec<Vec<Node>> {
    let (sx, sz) = QUADRANTS[q];
    let mut out = Vec::new();
    let bary = [Vec3::X, Vec3::Y, Vec3::Z];
    let triangle = Polygon { nodes: [0, 1, 2, 0, 0, 0, 0].map(|i| Node { position: p[i], bary: bary[i] }), count: 3 };
    // What lies beyond the current diamond; each band is cut from it, and the rest beyond the
    // next diamond is cut from the same polygon, so both sides of a diamond get the same points
    // (from the same edges).
    let mut rest = triangle.clip(Cut::X(sx)).clip(Cut::Z(sz)).clip(Cut::Chord(sx, sz, rho, 1.0));
    for next in active_bounds(rho, cuts).map(Some).chain([None]) {
        if rest.count == 0 {
            break;
        }
        let band = match next {
            None => rest.take(),
            Some(c) => {
                let (within, beyond) = (Cut::Chord(sx, sz, c, -1.0), Cut::Chord(sx, sz, c, 1.0));
                let (none, all) = rest.all_beyond(within);
                if none {
                    continue; // all of it lies beyond this band
                }
                if all {
                    rest.take()
                } else {
                    let band = rest.clip(within);
                    rest = rest.clip(beyond);
                    band
                }
            }
        };
        if band.count >= 3 {
            out.push(band.nodes[..band.count].to_vec());
        }
    }
    out
}
