//! The subdivide twin check's comparison of two triangle sets (tests/twins.rs).

use glam::Vec3;
use twister::core::scene::unpack_tangent;
use twister::encoding::types::DrawVertex;

/// Matches each CPU triangle to the nearest unused GPU triangle (searched among those whose
/// centroid and reference azimuth fall in neighbouring buckets: the GPU appends in another
/// order) and checks they are the same; at most `allowed` CPU triangles may lack a twin.
pub fn same_triangle_sets(cpu: &[DrawVertex], gpu: &[DrawVertex], allowed: usize) -> Result<(), String> {
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
            unmatched.push(format!("CPU triangle {t:?} has no GPU twin"));
            continue;
        };
        let close = |x: &[f32], y: &[f32]| x.iter().zip(y).all(|(p, q)| (p - q).abs() <= 1e-4 * (1.0 + p.abs()));
        let same = |a: &DrawVertex, b: &DrawVertex| {
            close(&a.position, &b.position)
                && close(&[a.theta_ref], &[b.theta_ref])
                && close(&a.normal, &b.normal)
                && close(&a.color, &b.color)
                && close(&a.uv, &b.uv)
                && close(&unpack_tangent(a.tangent).to_array(), &unpack_tangent(b.tangent).to_array())
                && a.material == b.material
        };
        match t.iter().zip(gpu_tris[best]).find(|(a, b)| !same(a, b)) {
            None => used[best] = true,
            Some((a, b)) => unmatched.push(format!("CPU vertex {a:?} differs from GPU vertex {b:?}")),
        }
    }
    if unmatched.len() > allowed {
        return Err(format!(
            "{} triangles without a twin (allowed {allowed}), first: {}",
            unmatched.len(),
            unmatched[0]
        ));
    }
    Ok(())
}
