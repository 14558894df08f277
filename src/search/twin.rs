//! The subdivide stage's GPU output against its CPU twin's: the same pieces, nodes and
//! triangles (as sets: the GPU appends in another order), within what the arithmetic of the
//! adapter explains. Used by the twin test (`tests/twins.rs`) and the random search.

use glam::Vec3;

use crate::core::scene::unpack_tangent;
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
    // Piece records come from the parts' edges alone: exact on a software adapter.
    let piece_slack = if software { 0 } else { cpu.pieces as usize / 100 };
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
    same_triangle_sets(&cpu.vertices, &gpu.vertices, slack(cpu.vertices.len() / 3), free_radius)
}

/// Matches each CPU triangle to the nearest unused GPU triangle (searched among those whose
/// centroid and reference azimuth fall in neighbouring buckets: the GPU appends in another
/// order) and checks they are the same; at most `allowed` CPU triangles may lack a twin, besides
/// any with a corner within `free_radius` of the vertical axis.
pub fn same_triangle_sets(
    cpu: &[DrawVertex],
    gpu: &[DrawVertex],
    allowed: usize,
    free_radius: f32,
) -> Result<(), String> {
    use std::collections::HashMap;
    if cpu.len().abs_diff(gpu.len()) / 3 > allowed {
        return Err(format!("CPU made {} triangles, GPU {}", cpu.len() / 3, gpu.len() / 3));
    }
    let key = |t: &[DrawVertex]| (t.iter().fold(Vec3::ZERO, |a, v| a + Vec3::from(v.position)) / 3.0, t[0].theta_ref);
    let cell = |c: Vec3, th: f32| {
        ((c.x * 1e3).floor() as i64, (c.y * 1e3).floor() as i64, (c.z * 1e3).floor() as i64, (th * 10.0).floor() as i64)
    };
    let gpu_tris: Vec<&[DrawVertex]> = gpu.chunks(3).collect();
    let mut buckets: HashMap<(i64, i64, i64, i64), Vec<usize>> = HashMap::new();
    for (j, t) in gpu_tris.iter().enumerate() {
        let (c, th) = key(t);
        buckets.entry(cell(c, th)).or_default().push(j);
    }
    let mut used = vec![false; gpu_tris.len()];
    let mut unmatched = Vec::new();
    for t in cpu.chunks(3) {
        let (c, th) = key(t);
        let k = cell(c, th);
        let mut best: Option<(f32, usize)> = None;
        for d in 0..81i64 {
            let (dx, dy, dz, dt) = (d % 3 - 1, d / 3 % 3 - 1, d / 9 % 3 - 1, d / 27 - 1);
            for &j in buckets.get(&(k.0 + dx, k.1 + dy, k.2 + dz, k.3 + dt)).into_iter().flatten() {
                if !used[j] {
                    let (c2, th2) = key(gpu_tris[j]);
                    let dist = (c2 - c).length() + (th2 - th).abs();
                    if best.is_none_or(|(bd, _)| dist < bd) {
                        best = Some((dist, j));
                    }
                }
            }
        }
        let Some((_, best)) = best else {
            unmatched.push((format!("CPU triangle {t:?} has no GPU twin"), axis_distance(t)));
            continue;
        };
        let close = |x: &[f32], y: &[f32]| x.iter().zip(y).all(|(p, q)| (p - q).abs() <= 1e-4 * (1.0 + p.abs()));
        // A point within 1e-4 of its distance from the viewer (not of each coordinate: a node
        // beside the vertical axis has x and z near 0, and a hardware GPU's sin, atan2 and acos
        // place it there within ~1e-4 m of the twin's, 0.1 mm on a floor 1.5 m below).
        let close_point = |x: [f32; 3], y: [f32; 3]| {
            (Vec3::from(x) - Vec3::from(y)).length() <= 1e-4 * (1.0 + Vec3::from(x).length())
        };
        let same = |a: &DrawVertex, b: &DrawVertex| {
            close_point(a.position, b.position)
                && close(&[a.theta_ref], &[b.theta_ref])
                && close(&a.normal, &b.normal)
                && close(&a.color, &b.color)
                && close(&a.uv, &b.uv)
                && close(&unpack_tangent(a.tangent).to_array(), &unpack_tangent(b.tangent).to_array())
                && a.material == b.material
                // Where the node is drawn off its projection: within 2·10⁻³ px (and 1 %).
                && a.offsets.iter().zip(&b.offsets).all(|(p, q)| (p - q).abs() <= 2e-3 + 1e-2 * p.abs())
        };
        match t.iter().zip(gpu_tris[best]).find(|(a, b)| !same(a, b)) {
            None => used[best] = true,
            Some((a, b)) => {
                unmatched.push((format!("CPU vertex {a:?} differs from GPU vertex {b:?}"), axis_distance(t)))
            }
        }
    }
    let counted: Vec<_> = unmatched.iter().filter(|(_, r)| *r >= free_radius).collect();
    if counted.len() > allowed {
        let near_axis = unmatched.iter().filter(|(_, r)| *r < 1e-2).count();
        return Err(format!(
            "{} triangles without a twin ({} counted, allowed {allowed}; {near_axis} with a corner within 1 cm of the vertical axis), first: {}",
            unmatched.len(),
            counted.len(),
            counted[0].0
        ));
    }
    Ok(())
}

/// The distance of a triangle's nearest corner from the vertical axis through the viewer.
fn axis_distance(t: &[DrawVertex]) -> f32 {
    t.iter().map(|v| v.position[0].hypot(v.position[2])).fold(f32::INFINITY, f32::min)
}
