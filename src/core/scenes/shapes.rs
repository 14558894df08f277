//! Closed meshes for property tests and the random search (`twister::search`): icospheres, boxes
//! whose faces are grids, tori. Shared corners are shared indices, so shared edges have
//! bit-identical end points, as a mesh loaded from a file has them.

use std::collections::HashMap;

use glam::Vec3;

use crate::core::scenes::scene::{Scene, SceneVertex};

/// A mesh as positions and triangle indices (counter-clockwise seen from outside).
#[derive(Clone, Debug, PartialEq)]
pub struct ClosedMesh {
    pub name: String,
    pub positions: Vec<Vec3>,
    pub indices: Vec<u32>,
}

impl ClosedMesh {
    /// The unit icosahedron's faces split `level` times, each new node pushed onto the unit sphere.
    pub fn icosphere(level: u32) -> ClosedMesh {
        let t = (1.0 + 5f32.sqrt()) / 2.0;
        let mut positions: Vec<Vec3> = [
            [-1.0, t, 0.0],
            [1.0, t, 0.0],
            [-1.0, -t, 0.0],
            [1.0, -t, 0.0],
            [0.0, -1.0, t],
            [0.0, 1.0, t],
            [0.0, -1.0, -t],
            [0.0, 1.0, -t],
            [t, 0.0, -1.0],
            [t, 0.0, 1.0],
            [-t, 0.0, -1.0],
            [-t, 0.0, 1.0],
        ]
        .map(|p| Vec3::from(p).normalize())
        .to_vec();
        let mut faces: Vec<[u32; 3]> = vec![
            [0, 11, 5],
            [0, 5, 1],
            [0, 1, 7],
            [0, 7, 10],
            [0, 10, 11],
            [1, 5, 9],
            [5, 11, 4],
            [11, 10, 2],
            [10, 7, 6],
            [7, 1, 8],
            [3, 9, 4],
            [3, 4, 2],
            [3, 2, 6],
            [3, 6, 8],
            [3, 8, 9],
            [4, 9, 5],
            [2, 4, 11],
            [6, 2, 10],
            [8, 6, 7],
            [9, 8, 1],
        ];
        for _ in 0..level {
            let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
            let mut next = Vec::new();
            for f in &faces {
                let mut m = [0u32; 3];
                for e in 0..3 {
                    let (a, b) = (f[e].min(f[(e + 1) % 3]), f[e].max(f[(e + 1) % 3]));
                    m[e] = *mid.entry((a, b)).or_insert_with(|| {
                        positions.push(((positions[a as usize] + positions[b as usize]) * 0.5).normalize());
                        positions.len() as u32 - 1
                    });
                }
                next.extend([[f[0], m[0], m[2]], [f[1], m[1], m[0]], [f[2], m[2], m[1]], [m[0], m[1], m[2]]]);
            }
            faces = next;
        }
        ClosedMesh { name: format!("icosphere {level}"), positions, indices: faces.concat() }
    }

    /// The surface of [−1, 1]³, each face a g×g grid of quads (two triangles each).
    pub fn grid_box(g: u32) -> ClosedMesh {
        let g = g.max(1);
        let mut index: HashMap<[u32; 3], u32> = HashMap::new();
        let mut positions = Vec::new();
        let mut indices = Vec::new();
        let mut id = |c: [u32; 3], positions: &mut Vec<Vec3>| -> u32 {
            *index.entry(c).or_insert_with(|| {
                positions.push(Vec3::from(c.map(|k| 2.0 * k as f32 / g as f32 - 1.0)));
                positions.len() as u32 - 1
            })
        };
        for axis in 0..3 {
            for side in [0, g] {
                for i in 0..g {
                    for j in 0..g {
                        let at = |a: u32, b: u32| {
                            let mut c = [0; 3];
                            c[axis] = side;
                            c[(axis + 1) % 3] = a;
                            c[(axis + 2) % 3] = b;
                            c
                        };
                        let q = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)].map(|c| id(c, &mut positions));
                        if side == 0 {
                            indices.extend([q[0], q[2], q[1], q[0], q[3], q[2]]);
                        } else {
                            indices.extend([q[0], q[1], q[2], q[0], q[2], q[3]]);
                        }
                    }
                }
            }
        }
        ClosedMesh { name: format!("box {g}"), positions, indices }
    }

    /// A torus of major radius 1 and minor radius 0.4 about the y axis, n × m quads.
    pub fn torus(n: u32, m: u32) -> ClosedMesh {
        let (n, m) = (n.max(3), m.max(3));
        let mut positions = Vec::new();
        for i in 0..n {
            for j in 0..m {
                let (a, b) = (std::f32::consts::TAU * i as f32 / n as f32, std::f32::consts::TAU * j as f32 / m as f32);
                let r = 1.0 + 0.4 * b.cos();
                positions.push(Vec3::new(r * a.cos(), 0.4 * b.sin(), r * a.sin()));
            }
        }
        let id = |i: u32, j: u32| (i % n) * m + j % m;
        let mut indices = Vec::new();
        for i in 0..n {
            for j in 0..m {
                indices.extend([id(i, j), id(i + 1, j + 1), id(i + 1, j), id(i, j), id(i, j + 1), id(i + 1, j + 1)]);
            }
        }
        ClosedMesh { name: format!("torus {n}x{m}"), positions, indices }
    }

    /// The mesh scaled by `scale` and moved to `centre`.
    pub fn placed(&self, centre: Vec3, scale: f32) -> ClosedMesh {
        ClosedMesh { positions: self.positions.iter().map(|&p| p * scale + centre).collect(), ..self.clone() }
    }

    /// Two meshes as one (the second's indices shifted).
    pub fn together(&self, other: &ClosedMesh) -> ClosedMesh {
        let base = self.positions.len() as u32;
        ClosedMesh {
            name: format!("{}, {}", self.name, other.name),
            positions: self.positions.iter().chain(&other.positions).copied().collect(),
            indices: self.indices.iter().copied().chain(other.indices.iter().map(|i| i + base)).collect(),
        }
    }

    /// Scene vertices of one colour, with the faces' area-weighted normals.
    pub fn vertices(&self, color: [f32; 4]) -> Vec<SceneVertex> {
        let mut vertices: Vec<SceneVertex> = self
            .positions
            .iter()
            .map(|p| SceneVertex { position: p.to_array(), color, ..Default::default() })
            .collect();
        crate::core::scenes::scene::compute_normals(&mut vertices, &self.indices);
        vertices
    }

    /// Adds the mesh to a scene as one object named after it.
    pub fn add_to(&self, scene: &mut Scene, color: [f32; 4]) {
        scene.add_mesh(self.name.clone(), &self.vertices(color), &self.indices);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every edge of each shape is used by exactly two triangles, once in each direction.
    #[test]
    fn the_shapes_are_closed_and_consistently_wound() {
        for mesh in [ClosedMesh::icosphere(2), ClosedMesh::grid_box(3), ClosedMesh::torus(12, 8)] {
            let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
            for t in mesh.indices.chunks(3) {
                for e in 0..3 {
                    *directed.entry((t[e], t[(e + 1) % 3])).or_default() += 1;
                }
            }
            for (&(a, b), &n) in &directed {
                assert_eq!(n, 1, "{}: edge {a}→{b} used {n} times", mesh.name);
                assert_eq!(directed.get(&(b, a)), Some(&1), "{}: edge {a}–{b} open", mesh.name);
            }
            // Counter-clockwise seen from outside: the signed volume is positive.
            let volume: f32 = mesh
                .indices
                .chunks(3)
                .map(|t| {
                    let p = [0, 1, 2].map(|k| mesh.positions[t[k] as usize]);
                    p[0].dot(p[1].cross(p[2])) / 6.0
                })
                .sum();
            assert!(volume > 0.0, "{}: signed volume {volume}", mesh.name);
        }
    }
}
