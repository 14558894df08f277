//! The subdivide stage's GPU output against its CPU twin's: the same pieces, nodes and
//! triangles (as sets: the GPU appends in another order), within what the arithmetic of the
//! adapter explains. Used by the twin test (`tests/twins.rs`) and the random search.

use std::collections::HashMap;

use glam::Vec3;

use crate::core::scenes::scene::unpack_tangent;
use crate::encoding::subdivide::SubdivideOutput;
use crate::encoding::types::DrawVertex;
/// One GPU output of the subdivide stage against the twin's; `software`: the adapter is a CPU
/// one (lavapipe), whose arithmetic is the twin's but for fused multiply-adds.
pub fn compare_subdivided(gpu: &SubdivideOutput, cpu: &SubdivideOutput, software: bool) -> Result<(), String> {
    if cpu.cuts != gpu.cuts {
        return Err(format!("cuts around the axis: CPU {:#x}, GPU {:#x}", cpu.cuts, gpu.cuts));
    }
    // A measure that sits on a ceil boundary flips a division count with the last bit of its
    // inputs. A hardware GPU's sin, atan2 and acos differ from the CPU's in the last bits (seen
    // on an H100: 36 of 53,697 nodes in a case of random triangles): there at most 1 % of the
    // pieces, nodes and triangles may differ. On a software adapter (lavapipe: correctly rounded
    // maths, but fused multiply-adds where the twin rounds twice) the edges' and macro edges'
    // counts come out the twin's; a piece's rows measure every row and its diagonals, many more
    // measures, and one in 10⁴–10⁵ flips a row's width or the piece's choice between rows and
    // the lattice (one piece of 84 triangles in a case of 200 random triangles; two small ones,
    // 38 triangles, beside the axis in the cubemap's demo room once its pieces had no seam
    // copies): there 0.1 % plus two pieces (the largest piece's output) may differ. On hardware
    // an edge's count may
    // flip, and its part is planned again whole: 1 % plus one part (an H200 re-planned one of a
    // cube's parts, 745 of its 10,069 triangles: the cube's 12 triangles make parts of up to
    // 32² pieces each). Every other triangle is the twin's.
    let (one_piece, one_part) = (cpu.max_piece_output as usize, cpu.max_part_output as usize);
    let slack = |n: usize| if software { n / 1000 + 2 * one_piece } else { n / 100 + one_part };
    // Piece records come from the parts' edges alone: on a software adapter the twin's but where
    // an edge's measure sits on a ceil boundary and the WGSL's own atan2 (the fisheye's map)
    // rounds apart from the CPU's (2 or 3 of 1,100–2,200 fisheye pieces, 1 case in 1,000):
    // 0.2 % plus two.
    let piece_slack = if software { cpu.pieces as usize / 500 + 2 } else { cpu.pieces as usize / 100 };
    if cpu.pieces.abs_diff(gpu.pieces) as usize > piece_slack {
        return Err(format!("pieces: CPU {}, GPU {}", cpu.pieces, gpu.pieces));
    }
    // The balance counters: the largest output of one invocation (a piece one division more or
    // less moves them by a few): within 10 %.
    for (what, c, g) in [("max pieces", cpu.max_pieces, gpu.max_pieces), ("max output", cpu.max_output, gpu.max_output)]
    {
        if c.abs_diff(g) > c / 10 || (c == 0) != (g == 0) {
            return Err(format!("{what} per invocation: CPU {c}, GPU {g}"));
        }
    }
    if (cpu.max_sub_edge_px - gpu.max_sub_edge_px).abs() >= 1e-2 * (1.0 + cpu.max_sub_edge_px) {
        return Err(format!("max edge: CPU {}, GPU {}", cpu.max_sub_edge_px, gpu.max_sub_edge_px));
    }
    // The indexed output: as many shared nodes, every index within them.
    if cpu.nodes.len().abs_diff(gpu.nodes.len()) > slack(cpu.nodes.len()) {
        return Err(format!("nodes: CPU {}, GPU {}", cpu.nodes.len(), gpu.nodes.len()));
    }
    if let Some(i) = gpu.indices.iter().find(|&&i| i as usize >= gpu.nodes.len()) {
        return Err(format!("GPU index {i} beyond its {} nodes", gpu.nodes.len()));
    }
    // Within a centimetre of the vertical axis (the square cut around it, ρ ≤ 1 mm, and its
    // bands), where the sphere's measure of sub-millimetre edges under the pole is as
    // ill-conditioned as the azimuth there, a hardware GPU's last bits change the square's
    // lattice: an H200 drew 377 of the cubemap demo room's triangles there otherwise (the nodes
    // 0.3 mm from the nadir; the sphere culls them beyond its first row's centre, the cubemap's
    // down face draws them, 0.04° across). On a software adapter they must match too.
    let free_radius = if software { 0.0 } else { 1e-2 };
    // On a software adapter a flipped piece may also be larger than the twin's largest: the
    // triangles without a twin then pass where both sides' cover the same surface, re-triangulated
    // (a 310° fisheye's piece flipped between rows and the lattice, 35 triangles where the
    // twin's largest piece made 8, once in 2,000 cases).
    same_triangle_sets(&cpu.vertices, &gpu.vertices, slack(cpu.vertices.len() / 3), software, free_radius)
}

/// Matches each CPU triangle to a GPU triangle the same (the GPU appends in another order):
/// first those whose corners and reference azimuth are the twin's to the bit (most, on a
/// software adapter), found by hashing; then the rest to the nearest unused one among those in
/// neighbouring buckets ([`Bucket`]). At most `allowed` CPU triangles may lack a twin, or any
/// number where `retriangulated` and the triangles without a twin on both sides cover the same
/// surface ([`same_surface`]), besides any with a corner within `free_radius` of the vertical
/// axis.
pub fn same_triangle_sets(
    cpu: &[DrawVertex],
    gpu: &[DrawVertex],
    allowed: usize,
    retriangulated: bool,
    free_radius: f32,
) -> Result<(), String> {
    if !retriangulated && cpu.len().abs_diff(gpu.len()) / 3 > allowed {
        return Err(format!("CPU made {} triangles, GPU {}", cpu.len() / 3, gpu.len() / 3));
    }
    let gpu_tris: Vec<&[DrawVertex]> = gpu.chunks(3).collect();
    let mut exact: HashMap<[u32; 10], Vec<usize>> = HashMap::new();
    let mut buckets: HashMap<Bucket, Vec<usize>> = HashMap::new();
    for (j, t) in gpu_tris.iter().enumerate() {
        exact.entry(exact_key(t)).or_default().push(j);
        buckets.entry(bucket(t, 0)).or_default().push(j);
    }
    let mut used = vec![false; gpu_tris.len()];
    let mut rest = Vec::new();
    for t in cpu.chunks(3) {
        let twin = exact.get_mut(&exact_key(t)).and_then(|list| {
            let at = list.iter().position(|&j| !used[j] && first_difference(t, gpu_tris[j]).is_none())?;
            Some(list.swap_remove(at))
        });
        match twin {
            Some(j) => used[j] = true,
            None => rest.push(t),
        }
    }
    for list in buckets.values_mut() {
        list.retain(|&j| !used[j]);
    }
    let mut unmatched = Vec::new();
    for t in rest {
        let Some(best) = nearest_unused(t, &gpu_tris, &buckets, &used) else {
            unmatched.push((format!("CPU triangle {t:?} has no GPU twin"), axis_distance(t), t));
            continue;
        };
        match first_difference(t, gpu_tris[best]) {
            None => used[best] = true,
            Some((a, b)) => {
                unmatched.push((format!("CPU vertex {a:?} differs from GPU vertex {b:?}"), axis_distance(t), t))
            }
        }
    }
    let counted: Vec<_> = unmatched.iter().filter(|(_, r, _)| *r >= free_radius).collect();
    // Re-triangulated pieces: the triangles without a twin on the CPU's side and those no CPU
    // triangle took on the GPU's cover the same surface (the same area, the same box).
    let gpu_left: Vec<&[DrawVertex]> = gpu_tris.iter().zip(&used).filter(|(_, u)| !**u).map(|(t, _)| *t).collect();
    let cpu_left: Vec<&[DrawVertex]> = counted.iter().map(|(_, _, t)| *t).collect();
    if counted.len() > allowed && !(retriangulated && same_surface(&cpu_left, &gpu_left)) {
        let near_axis = unmatched.iter().filter(|(_, r, _)| *r < 1e-2).count();
        return Err(format!(
            "{} triangles without a twin ({} counted, allowed {allowed}{}; {near_axis} with a corner within 1 cm of the vertical axis), first: {}",
            unmatched.len(),
            counted.len(),
            if retriangulated { ", and not a re-triangulation of the same surface" } else { "" },
            counted[0].0
        ));
    }
    Ok(())
}

/// Whether two sets of triangles cover the same surface, as a piece re-triangulated does: the
/// same total area (within 10⁻³) and the same bounding box (within 10⁻³ of its size).
fn same_surface(a: &[&[DrawVertex]], b: &[&[DrawVertex]]) -> bool {
    let area = |ts: &[&[DrawVertex]]| -> f64 {
        ts.iter()
            .map(|t| {
                let [p, q, r] = [0, 1, 2].map(|k| Vec3::from(t[k].position).as_dvec3());
                0.5 * (q - p).cross(r - p).length()
            })
            .sum()
    };
    let bounds = |ts: &[&[DrawVertex]]| {
        ts.iter().flat_map(|t| t.iter()).fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), v| {
            (lo.min(Vec3::from(v.position)), hi.max(Vec3::from(v.position)))
        })
    };
    if a.is_empty() || b.is_empty() {
        return a.is_empty() && b.is_empty();
    }
    let (area_a, area_b) = (area(a), area(b));
    let ((lo_a, hi_a), (lo_b, hi_b)) = (bounds(a), bounds(b));
    let size = (hi_a - lo_a).length().max(1e-6);
    (area_a - area_b).abs() <= 1e-3 * area_a.max(area_b) + 1e-12
        && (lo_a - lo_b).abs().max_element() <= 1e-3 * size
        && (hi_a - hi_b).abs().max_element() <= 1e-3 * size
}

/// A triangle's bucket: its scale level ℓ (2^ℓ ≤ 1 + its farthest corner's distance), its
/// centroid in cells of 2·10⁻⁴·2^ℓ (at least the twin's tolerance on its corners, so a twin lies
/// in a neighbouring cell of a neighbouring level) and its reference azimuth in tenths of a
/// radian: small, so that the thousands of tiny triangles beside the axis or the eye circle do
/// not share one (a quadratic scan over one took minutes).
type Bucket = (i64, i64, i64, i64, i64);

/// A triangle's centroid and reference azimuth.
fn centroid(t: &[DrawVertex]) -> (Vec3, f32) {
    (t.iter().fold(Vec3::ZERO, |a, v| a + Vec3::from(v.position)) / 3.0, t[0].theta_ref)
}

/// The [`Bucket`] of triangle `t`, its level moved by `dl`.
fn bucket(t: &[DrawVertex], dl: i64) -> Bucket {
    let far = t.iter().map(|v| Vec3::from(v.position).length()).fold(0.0f32, f32::max);
    let l = (1.0 + far).log2().floor().clamp(0.0, 60.0) as i64 + dl;
    let s = 2e-4 * (l as f32).exp2();
    let (c, th) = centroid(t);
    (l, (c.x / s).floor() as i64, (c.y / s).floor() as i64, (c.z / s).floor() as i64, (th * 10.0).floor() as i64)
}

/// The exact bits of a triangle's corners and reference azimuth.
fn exact_key(t: &[DrawVertex]) -> [u32; 10] {
    let mut k = [0; 10];
    for (i, v) in t.iter().enumerate() {
        k[3 * i..3 * i + 3].copy_from_slice(&v.position.map(f32::to_bits));
    }
    k[9] = t[0].theta_ref.to_bits();
    k
}

/// The unused GPU triangle nearest CPU triangle `t` (centroid and reference azimuth) among the
/// neighbouring buckets of the neighbouring levels.
fn nearest_unused(
    t: &[DrawVertex],
    gpu_tris: &[&[DrawVertex]],
    buckets: &HashMap<Bucket, Vec<usize>>,
    used: &[bool],
) -> Option<usize> {
    let (c, th) = centroid(t);
    let mut best: Option<(f32, usize)> = None;
    for d in 0..243i64 {
        let (dx, dy, dz, dt, dl) = (d % 3 - 1, d / 3 % 3 - 1, d / 9 % 3 - 1, d / 27 % 3 - 1, d / 81 - 1);
        let k = bucket(t, dl);
        for &j in buckets.get(&(k.0, k.1 + dx, k.2 + dy, k.3 + dz, k.4 + dt)).into_iter().flatten() {
            if !used[j] {
                let (c2, th2) = centroid(gpu_tris[j]);
                let dist = (c2 - c).length() + (th2 - th).abs();
                if best.is_none_or(|(bd, _)| dist < bd) {
                    best = Some((dist, j));
                }
            }
        }
    }
    best.map(|(_, j)| j)
}

/// The first corner of CPU triangle `t` that differs from GPU triangle `g`'s, if any. Every
/// value within 1e-4 (relative); a point within 1e-4 of its distance from the viewer (not of
/// each coordinate: a node beside the vertical axis has x and z near 0, and a hardware GPU's
/// sin, atan2 and acos place it there within ~1e-4 m of the twin's, 0.1 mm on a floor 1.5 m
/// below); the reference azimuth also within what that tolerance turns an azimuth by at the
/// triangle's nearest distance from the axis (a node 5·10⁻⁵ m beside it, placed 3·10⁻⁸ m apart,
/// turns 4·10⁻⁴ rad; drawn there, at a pole of the sphere or the cubemap, its azimuth does not
/// move it); where a node is drawn off its projection, within 2·10⁻³ px (and 1 %).
fn first_difference(t: &[DrawVertex], g: &[DrawVertex]) -> Option<(DrawVertex, DrawVertex)> {
    let close = |x: &[f32], y: &[f32]| x.iter().zip(y).all(|(p, q)| (p - q).abs() <= 1e-4 * (1.0 + p.abs()));
    let r = axis_distance(t);
    let same = |a: &DrawVertex, b: &DrawVertex| {
        let length = Vec3::from(a.position).length();
        let turn = 1e-4 * (1.0 + length) / r.max(1e-30);
        (Vec3::from(a.position) - Vec3::from(b.position)).length() <= 1e-4 * (1.0 + length)
            && (a.theta_ref - b.theta_ref).abs() <= 1e-4 * (1.0 + a.theta_ref.abs()) + turn
            && close(&a.normal, &b.normal)
            && close(&a.color, &b.color)
            && close(&a.uv, &b.uv)
            && close(&unpack_tangent(a.tangent).to_array(), &unpack_tangent(b.tangent).to_array())
            && a.material == b.material
            && a.offsets.iter().zip(&b.offsets).all(|(p, q)| (p - q).abs() <= 2e-3 + 1e-2 * p.abs())
    };
    t.iter().zip(g).find(|(a, b)| !same(a, b)).map(|(a, b)| (*a, *b))
}

/// The distance of a triangle's nearest corner from the vertical axis through the viewer.
fn axis_distance(t: &[DrawVertex]) -> f32 {
    t.iter().map(|v| v.position[0].hypot(v.position[2])).fold(f32::INFINITY, f32::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(p: [[f32; 3]; 3]) -> Vec<DrawVertex> {
        p.iter().map(|&q| DrawVertex { position: q, ..Default::default() }).collect()
    }

    /// A square re-triangulated (two triangles against four) passes where re-triangulation is
    /// allowed; the same with a triangle missing, or without the allowance, fails.
    #[test]
    fn a_retriangulated_piece_passes_and_a_lost_triangle_does_not() {
        let (a, b, c, d, m) =
            ([1.0, 0.0, -2.0], [2.0, 0.0, -2.0], [2.0, 1.0, -2.0], [1.0, 1.0, -2.0], [1.5, 0.5, -2.0]);
        let cpu: Vec<DrawVertex> = [tri([a, b, c]), tri([a, c, d])].concat();
        let four = [tri([a, b, m]), tri([b, c, m]), tri([c, d, m]), tri([d, a, m])];
        let gpu: Vec<DrawVertex> = four.concat();
        assert!(same_triangle_sets(&cpu, &gpu, 0, true, 0.0).is_ok());
        assert!(same_triangle_sets(&cpu, &gpu, 0, false, 0.0).is_err());
        let lost: Vec<DrawVertex> = four[..3].concat();
        assert!(same_triangle_sets(&cpu, &lost, 0, true, 0.0).is_err(), "a quarter of the square lost");
    }
}
