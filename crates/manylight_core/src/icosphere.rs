//! The sphere proxy of deferred light volumes: a subdivided icosahedron scaled so that it
//! contains the unit sphere (every face lies outside it), so a light's proxy covers every pixel
//! the light can reach.

use glam::Vec3;

/// A closed triangle mesh around the origin, faces wound counter-clockwise seen from outside.
#[derive(Clone, Debug, PartialEq)]
pub struct Icosphere {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Triangle list.
    pub indices: Vec<u16>,
}

impl Icosphere {
    /// An icosahedron subdivided `subdivisions` times (at most 5: 20 · 4^5 triangles fit 16-bit
    /// indices), scaled so that it circumscribes the unit sphere.
    pub fn circumscribing_unit_sphere(subdivisions: u32) -> Icosphere {
        let mut mesh = icosahedron();
        for _ in 0..subdivisions.min(5) {
            mesh = subdivide(&mesh);
        }
        let inradius = mesh.min_face_distance();
        // Scale up so the closest face plane is at distance >= 1 (a hair more for rounding).
        let scale = (1.0 / inradius) * (1.0 + 1e-5);
        for p in &mut mesh.positions {
            *p *= scale;
        }
        mesh
    }

    /// Smallest distance from the origin to the plane of any face.
    pub fn min_face_distance(&self) -> f32 {
        self.triangles()
            .map(|[a, b, c]| {
                let n = (b - a).cross(c - a).normalize_or_zero();
                n.dot(a)
            })
            .fold(f32::INFINITY, f32::min)
    }

    /// The triangles' corner positions.
    pub fn triangles(&self) -> impl Iterator<Item = [Vec3; 3]> + '_ {
        self.indices.chunks_exact(3).map(|t| {
            [self.positions[t[0] as usize], self.positions[t[1] as usize], self.positions[t[2] as usize]]
        })
    }
}

fn icosahedron() -> Icosphere {
    let t = (1.0 + 5.0f32.sqrt()) / 2.0;
    let positions = [
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
    .map(|p| Vec3::from_array(p).normalize())
    .to_vec();
    #[rustfmt::skip]
    let indices = vec![
        0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11,
        1, 5, 9, 5, 11, 4, 11, 10, 2, 10, 7, 6, 7, 1, 8,
        3, 9, 4, 3, 4, 2, 3, 2, 6, 3, 6, 8, 3, 8, 9,
        4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6, 7, 9, 8, 1,
    ];
    Icosphere { positions, indices }
}

/// Splits each triangle into four, new vertices pushed onto the unit sphere.
fn subdivide(mesh: &Icosphere) -> Icosphere {
    let mut positions = mesh.positions.clone();
    let mut midpoints = std::collections::HashMap::new();
    let mut midpoint = |a: u16, b: u16, positions: &mut Vec<Vec3>| -> u16 {
        let key = (a.min(b), a.max(b));
        *midpoints.entry(key).or_insert_with(|| {
            positions.push(((positions[a as usize] + positions[b as usize]) * 0.5).normalize());
            (positions.len() - 1) as u16
        })
    };
    let mut indices = Vec::with_capacity(mesh.indices.len() * 4);
    for t in mesh.indices.chunks_exact(3) {
        let (a, b, c) = (t[0], t[1], t[2]);
        let ab = midpoint(a, b, &mut positions);
        let bc = midpoint(b, c, &mut positions);
        let ca = midpoint(c, a, &mut positions);
        indices.extend_from_slice(&[a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca]);
    }
    Icosphere { positions, indices }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_face_lies_outside_the_unit_sphere_and_faces_outwards() {
        for level in 0..=3 {
            let s = Icosphere::circumscribing_unit_sphere(level);
            assert_eq!(s.indices.len(), 60 * 4usize.pow(level));
            for [a, b, c] in s.triangles() {
                let n = (b - a).cross(c - a).normalize();
                let d = n.dot(a);
                assert!(d >= 1.0, "level {level}: face plane at {d} cuts the unit sphere");
                assert!(n.dot((a + b + c) / 3.0) > 0.0, "level {level}: face wound inwards");
            }
        }
    }

    #[test]
    fn subdivision_makes_the_proxy_tighter() {
        let radius = |l| {
            let s = Icosphere::circumscribing_unit_sphere(l);
            s.positions.iter().map(|p| p.length()).fold(0.0f32, f32::max)
        };
        assert!(radius(2) < radius(1) && radius(1) < radius(0));
        assert!(radius(2) < 1.06, "level 2 proxy overshoots by {}", radius(2));
    }
}
