//! The subdivide twin check's comparison of two triangle sets (tests/twins.rs).

use glam::Vec3;
use twister::core::scene::unpack_tangent;
use twister::encoding::types::DrawVertex;

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
