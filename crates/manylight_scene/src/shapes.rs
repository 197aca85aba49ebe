//! Procedural meshes for the generated scenes: boxes, cylinders, spheres and arches, each
//! centred on its own origin with unit normals, counter-clockwise front faces and texture
//! coordinates in world units times `uv_scale` (so textures tile at a constant density).

use glam::{Vec2, Vec3};
use manylight_core::{MeshData, Vertex};
use std::f32::consts::{PI, TAU};

/// Accumulates vertices and triangles.
#[derive(Default)]
struct Builder {
    vertices: Vec<Vertex>,
    indices: Vec<u32>,
}

impl Builder {
    fn vertex(&mut self, p: Vec3, n: Vec3, uv: Vec2) -> u32 {
        self.vertices.push(Vertex {
            position: p.to_array(),
            normal: n.to_array(),
            uv: uv.to_array(),
            tangent: [0.0; 4],
            uv1: [0.0; 2],
        });
        (self.vertices.len() - 1) as u32
    }

    /// A quad `a b c d`, counter-clockwise seen from the side `n` points to.
    fn quad(&mut self, p: [Vec3; 4], n: Vec3, uv: [Vec2; 4]) {
        let i: [u32; 4] = std::array::from_fn(|k| self.vertex(p[k], n, uv[k]));
        self.indices.extend_from_slice(&[i[0], i[1], i[2], i[0], i[2], i[3]]);
    }

    fn build(self, label: &str) -> MeshData {
        let mut mesh = MeshData { label: label.to_owned(), vertices: self.vertices, indices: self.indices };
        // Built-in shapes are small and ordinary: MikkTSpace always runs on them.
        let method = mesh.generate_tangents();
        debug_assert_eq!(method, manylight_core::mesh::TangentMethod::MikkTSpace, "{label}");
        mesh
    }
}

/// An axis-aligned box of full extents `size`, centred on the origin.
pub fn cuboid(label: &str, size: Vec3, uv_scale: f32) -> MeshData {
    let h = size * 0.5;
    let mut b = Builder::default();
    // For each face: normal, and the two in-plane axes (u, v) with u x v = n.
    let faces = [
        (Vec3::X, Vec3::NEG_Z, Vec3::Y),
        (Vec3::NEG_X, Vec3::Z, Vec3::Y),
        (Vec3::Y, Vec3::X, Vec3::NEG_Z),
        (Vec3::NEG_Y, Vec3::X, Vec3::Z),
        (Vec3::Z, Vec3::X, Vec3::Y),
        (Vec3::NEG_Z, Vec3::NEG_X, Vec3::Y),
    ];
    for (n, u, v) in faces {
        let c = n * h;
        let (hu, hv) = ((u * h).length(), (v * h).length());
        let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
        let p = corners.map(|(su, sv)| c + u * (su * hu) + v * (sv * hv));
        let uv = corners.map(|(su, sv)| Vec2::new((su + 1.0) * hu, (1.0 - sv) * hv) * uv_scale);
        b.quad(p, n, uv);
    }
    b.build(label)
}

/// A capped cylinder along Y of radius `radius` and height `height`, centred on the origin.
pub fn cylinder(label: &str, radius: f32, height: f32, segments: u32, uv_scale: f32) -> MeshData {
    let segments = segments.max(3);
    let mut b = Builder::default();
    let hy = height * 0.5;
    let circumference = TAU * radius;
    for s in 0..segments {
        let (a0, a1) = (s as f32 / segments as f32 * TAU, (s + 1) as f32 / segments as f32 * TAU);
        let d0 = Vec3::new(a0.cos(), 0.0, -a0.sin());
        let d1 = Vec3::new(a1.cos(), 0.0, -a1.sin());
        let (u0, u1) =
            (s as f32 / segments as f32 * circumference, (s + 1) as f32 / segments as f32 * circumference);
        let base = b.vertices.len() as u32;
        for (d, u) in [(d0, u0), (d1, u1)] {
            b.vertex(d * radius - Vec3::Y * hy, d, Vec2::new(u, height) * uv_scale);
            b.vertex(d * radius + Vec3::Y * hy, d, Vec2::new(u, 0.0) * uv_scale);
        }
        // base: bottom0, top0, bottom1, top1; side faces outward (CCW seen from outside).
        b.indices.extend_from_slice(&[base, base + 2, base + 3, base, base + 3, base + 1]);
        for (y, n) in [(hy, Vec3::Y), (-hy, Vec3::NEG_Y)] {
            let c = b.vertex(Vec3::Y * y, n, Vec2::splat(radius) * uv_scale);
            let p0 = d0 * radius + Vec3::Y * y;
            let p1 = d1 * radius + Vec3::Y * y;
            let i0 = b.vertex(p0, n, (Vec2::new(p0.x, p0.z) + radius) * uv_scale);
            let i1 = b.vertex(p1, n, (Vec2::new(p1.x, p1.z) + radius) * uv_scale);
            // Angles grow counter-clockwise seen from +Y, so (c, i0, i1) faces +Y.
            if n.y > 0.0 {
                b.indices.extend_from_slice(&[c, i0, i1]);
            } else {
                b.indices.extend_from_slice(&[c, i1, i0]);
            }
        }
    }
    b.build(label)
}

/// A UV sphere of radius `radius` with `rings` latitude bands and `segments` longitude
/// bands. With `inward`, normals point to the centre and faces are wound to be seen from
/// inside.
pub fn uv_sphere(label: &str, radius: f32, rings: u32, segments: u32, inward: bool) -> MeshData {
    let (rings, segments) = (rings.max(2), segments.max(3));
    let mut b = Builder::default();
    for r in 0..=rings {
        let theta = r as f32 / rings as f32 * PI;
        for s in 0..=segments {
            let phi = s as f32 / segments as f32 * TAU;
            let d = Vec3::new(theta.sin() * phi.cos(), theta.cos(), -theta.sin() * phi.sin());
            let n = if inward { -d } else { d };
            b.vertex(d * radius, n, Vec2::new(s as f32 / segments as f32, r as f32 / rings as f32));
        }
    }
    let row = segments + 1;
    for r in 0..rings {
        for s in 0..segments {
            let (a, bb) = (r * row + s, r * row + s + 1);
            let (c, d) = ((r + 1) * row + s + 1, (r + 1) * row + s);
            // a: top-left, d: below a. Outward CCW: (a, d, c), (a, c, bb); the pole rows
            // have one degenerate triangle each, which is skipped.
            let mut tris = Vec::with_capacity(2);
            if r + 1 < rings {
                tris.push([a, d, c]);
            }
            if r > 0 {
                tris.push([a, c, bb]);
            }
            for t in tris {
                if inward {
                    b.indices.extend_from_slice(&[t[0], t[2], t[1]]);
                } else {
                    b.indices.extend_from_slice(&t);
                }
            }
        }
    }
    b.build(label)
}

/// A semicircular arch in the XY plane (opening downwards, springing at y = 0), inner radius
/// `inner`, outer radius `outer`, extruded `depth` along Z and centred on Z = 0.
pub fn arch(label: &str, inner: f32, outer: f32, depth: f32, segments: u32, uv_scale: f32) -> MeshData {
    let segments = segments.max(2);
    let mut b = Builder::default();
    let hz = depth * 0.5;
    for s in 0..segments {
        let (a0, a1) = (s as f32 / segments as f32 * PI, (s + 1) as f32 / segments as f32 * PI);
        let (d0, d1) = (Vec3::new(a0.cos(), a0.sin(), 0.0), Vec3::new(a1.cos(), a1.sin(), 0.0));
        let (i0, i1, o0, o1) = (d0 * inner, d1 * inner, d0 * outer, d1 * outer);
        let z = Vec3::Z * hz;
        let uv = |p: Vec3| Vec2::new(p.x, -p.y) * uv_scale;
        // Front (+Z): angles grow counter-clockwise seen from +Z.
        b.quad([i0 + z, o0 + z, o1 + z, i1 + z], Vec3::Z, [i0, o0, o1, i1].map(uv));
        b.quad([i1 - z, o1 - z, o0 - z, i0 - z], Vec3::NEG_Z, [i1, o1, o0, i0].map(uv));
        let (l0, l1) = (a0 * outer * uv_scale, a1 * outer * uv_scale);
        let uvs = [
            Vec2::new(l0, 0.0),
            Vec2::new(l1, 0.0),
            Vec2::new(l1, depth * uv_scale),
            Vec2::new(l0, depth * uv_scale),
        ];
        // Outer surface (extrados) faces outward, inner surface (intrados) faces the centre.
        let dm = (d0 + d1).normalize();
        b.quad([o0 + z, o0 - z, o1 - z, o1 + z], dm, uvs);
        b.quad([i0 - z, i0 + z, i1 + z, i1 - z], -dm, uvs);
    }
    b.build(label)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every triangle's geometric normal agrees with its vertex normals (winding check).
    fn assert_winding(m: &MeshData) {
        m.validate().expect("valid mesh");
        for t in m.indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| Vec3::from(m.vertices[i as usize].position));
            let g = (b - a).cross(c - a);
            if g.length() < 1e-9 {
                continue;
            }
            let n: Vec3 = t.iter().map(|&i| Vec3::from(m.vertices[i as usize].normal)).sum();
            assert!(g.dot(n) > 0.0, "{}: triangle {t:?} is wound against its normals", m.label);
        }
    }

    #[test]
    fn shapes_are_wound_with_their_normals() {
        assert_winding(&cuboid("box", Vec3::new(1.0, 2.0, 3.0), 1.0));
        assert_winding(&cylinder("cyl", 0.5, 2.0, 12, 1.0));
        assert_winding(&uv_sphere("sphere", 1.0, 8, 12, false));
        assert_winding(&uv_sphere("inward", 1.0, 8, 12, true));
        assert_winding(&arch("arch", 2.0, 2.5, 0.8, 8, 1.0));
    }

    #[test]
    fn inward_sphere_normals_point_to_the_centre() {
        let m = uv_sphere("s", 50.0, 24, 48, true);
        for v in &m.vertices {
            assert!(Vec3::from(v.normal).dot(Vec3::from(v.position)) < 0.0);
        }
    }
}

/// A grid of metallic-roughness spheres, one material each: a row per metalness, a column per
/// roughness, one unit apart and centred on the origin (the first row on top), facing +Z. Tests
/// and measurements that compare shading with a reference ray-cast the same spheres
/// ([`SphereGrid::centre`], [`SphereGrid::radius`]).
#[derive(Clone, Debug, PartialEq)]
pub struct SphereGrid {
    /// Sphere radius (below 0.5 leaves gaps between them).
    pub radius: f32,
    /// Latitude rings and longitude segments of each sphere's mesh.
    pub rings: u32,
    /// See `rings`.
    pub segments: u32,
    /// Linear base colour of every sphere.
    pub albedo: Vec3,
    /// Metalness of each row, top first.
    pub metallic: Vec<f32>,
    /// Perceptual roughness of each column, left first.
    pub roughness: Vec<f32>,
}

impl SphereGrid {
    /// Centre of the sphere at `row`, `column`.
    pub fn centre(&self, row: usize, column: usize) -> Vec3 {
        let half_w = (self.roughness.len() as f32 - 1.0) * 0.5;
        let half_h = (self.metallic.len() as f32 - 1.0) * 0.5;
        Vec3::new(column as f32 - half_w, half_h - row as f32, 0.0)
    }

    /// The nearest sphere the ray from `origin` along unit `dir` enters in front of `origin`:
    /// the distance along the ray, and the sphere's row and column (the analytic spheres the
    /// meshes of [`SphereGrid::scene`] approximate).
    pub fn hit(&self, origin: Vec3, dir: Vec3) -> Option<(f32, usize, usize)> {
        let mut hit: Option<(f32, usize, usize)> = None;
        for row in 0..self.metallic.len() {
            for column in 0..self.roughness.len() {
                let oc = origin - self.centre(row, column);
                let b = oc.dot(dir);
                let disc = b * b - (oc.length_squared() - self.radius * self.radius);
                if disc < 0.0 {
                    continue;
                }
                let t = -b - disc.sqrt();
                if t > 0.0 && hit.is_none_or(|(best, _, _)| t < best) {
                    hit = Some((t, row, column));
                }
            }
        }
        hit
    }

    /// The spheres as a scene (no camera, no light): one mesh, a material per sphere named by
    /// its parameters.
    pub fn scene(&self, name: &str) -> crate::Scene {
        use manylight_core::{Color, MaterialData};
        use std::sync::Arc;
        let mut scene = crate::Scene { name: name.into(), ..crate::Scene::default() };
        scene.meshes.push(Arc::new(uv_sphere("sphere", self.radius, self.rings, self.segments, false)));
        for (row, &metallic) in self.metallic.iter().enumerate() {
            for (column, &roughness) in self.roughness.iter().enumerate() {
                scene.materials.push(Arc::new(MaterialData {
                    label: format!("metallic {metallic} roughness {roughness}"),
                    base_color: Color::linear_rgb(self.albedo.x, self.albedo.y, self.albedo.z),
                    metallic,
                    roughness,
                    ..MaterialData::default()
                }));
                scene.instances.push(crate::SceneInstance {
                    mesh: 0,
                    material: scene.materials.len() - 1,
                    transform: glam::Mat4::from_translation(self.centre(row, column)),
                });
            }
        }
        scene
    }
}
