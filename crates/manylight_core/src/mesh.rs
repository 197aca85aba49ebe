//! Triangle meshes as plain data.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec2, Vec3, Vec4};
use thiserror::Error;

pub mod tangents;

pub use tangents::{TangentFallback, TangentMethod};

/// Interleaved vertex as the GPU reads it (`shaders/common/vertex.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Vertex {
    /// Object-space position.
    pub position: [f32; 3],
    /// Object-space unit normal.
    pub normal: [f32; 3],
    /// Texture coordinate.
    pub uv: [f32; 2],
    /// Object-space unit tangent (xyz, along +u) and the handedness of the bitangent (w = ±1:
    /// `bitangent = w * cross(normal, tangent)`), as glTF's `TANGENT`. All zero when the mesh
    /// has none: normal maps then leave the normal as it is.
    pub tangent: [f32; 4],
    /// Second texture coordinate (glTF `TEXCOORD_1`), for textures whose
    /// [`UvChannel`](crate::UvChannel) is `Uv1`; zero when the mesh has none.
    pub uv1: [f32; 2],
}

/// A mesh whose data is not usable.
#[derive(Debug, Error, PartialEq)]
pub enum MeshError {
    /// An index points past the vertex array.
    #[error("index {index} at position {at} is out of range (mesh has {vertices} vertices)")]
    IndexOutOfRange {
        /// The index value.
        index: u32,
        /// Its position in the index list.
        at: usize,
        /// Vertices the mesh has.
        vertices: usize,
    },
    /// The index count is not a multiple of three.
    #[error("index count {0} is not a multiple of 3")]
    NotTriangles(usize),
    /// A position, normal or uv (either set) is NaN or infinite.
    #[error("vertex {0} has a non-finite attribute")]
    NonFinite(usize),
}

/// Axis-aligned bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Minimum corner.
    pub min: Vec3,
    /// Maximum corner.
    pub max: Vec3,
}

impl Aabb {
    /// The empty box (min = +inf, max = -inf); `extend` grows it.
    pub const EMPTY: Aabb = Aabb { min: Vec3::INFINITY, max: Vec3::NEG_INFINITY };

    /// Grows the box to contain `p`.
    pub fn extend(&mut self, p: Vec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    /// True when nothing was added.
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x
    }

    /// Centre of the box.
    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// Full size along each axis.
    pub fn size(&self) -> Vec3 {
        self.max - self.min
    }

    /// The box that contains this one after `m` is applied.
    pub fn transformed(&self, m: &Mat4) -> Aabb {
        let mut out = Aabb::EMPTY;
        if self.is_empty() {
            return out;
        }
        for i in 0..8 {
            let c = Vec3::new(
                if i & 1 == 0 { self.min.x } else { self.max.x },
                if i & 2 == 0 { self.min.y } else { self.max.y },
                if i & 4 == 0 { self.min.z } else { self.max.z },
            );
            out.extend(m.transform_point3(c));
        }
        out
    }

    /// Union of two boxes.
    pub fn union(&self, o: &Aabb) -> Aabb {
        Aabb { min: self.min.min(o.min), max: self.max.max(o.max) }
    }
}

/// An indexed triangle list (non-indexed input gets sequential indices).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshData {
    /// Name for logs and GPU labels.
    pub label: String,
    /// Vertices.
    pub vertices: Vec<Vertex>,
    /// Triangle list indices into `vertices`.
    pub indices: Vec<u32>,
}

impl MeshData {
    /// Builds a mesh from separate attribute arrays; missing normals are generated from the
    /// triangles (area-weighted smooth normals), missing uvs are zero.
    pub fn from_attributes(
        label: impl Into<String>,
        positions: &[Vec3],
        normals: Option<&[Vec3]>,
        uvs: Option<&[Vec2]>,
        indices: Option<Vec<u32>>,
    ) -> Result<MeshData, MeshError> {
        let indices = indices.unwrap_or_else(|| (0..positions.len() as u32).collect());
        let mut mesh = MeshData {
            label: label.into(),
            vertices: positions
                .iter()
                .enumerate()
                .map(|(i, p)| Vertex {
                    position: p.to_array(),
                    normal: normals.and_then(|n| n.get(i)).map_or([0.0; 3], |n| n.to_array()),
                    uv: uvs.and_then(|u| u.get(i)).map_or([0.0; 2], |u| u.to_array()),
                    tangent: [0.0; 4],
                    uv1: [0.0; 2],
                })
                .collect(),
            indices,
        };
        mesh.validate()?;
        if normals.is_none() {
            mesh.generate_normals();
        } else {
            mesh.normalize_normals();
        }
        Ok(mesh)
    }

    /// Checks indices and attributes.
    pub fn validate(&self) -> Result<(), MeshError> {
        if !self.indices.len().is_multiple_of(3) {
            return Err(MeshError::NotTriangles(self.indices.len()));
        }
        if let Some((at, &index)) =
            self.indices.iter().enumerate().find(|&(_, &i)| i as usize >= self.vertices.len())
        {
            return Err(MeshError::IndexOutOfRange { index, at, vertices: self.vertices.len() });
        }
        if let Some(i) = self.vertices.iter().position(|v| {
            !v.position.iter().chain(&v.normal).chain(&v.uv).chain(&v.uv1).all(|x| x.is_finite())
        }) {
            return Err(MeshError::NonFinite(i));
        }
        Ok(())
    }

    /// Sets the second texture coordinate of every vertex (`uv1[i]` for vertex `i`; vertices
    /// past its end get zero).
    pub fn set_uv1(&mut self, uv1: &[Vec2]) {
        for (i, v) in self.vertices.iter_mut().enumerate() {
            v.uv1 = uv1.get(i).map_or([0.0; 2], |u| u.to_array());
        }
    }

    /// Replaces the normals by area-weighted smooth normals of the triangles.
    pub fn generate_normals(&mut self) {
        let mut acc = vec![Vec3::ZERO; self.vertices.len()];
        for tri in self.indices.chunks_exact(3) {
            let [a, b, c] = [tri[0], tri[1], tri[2]].map(|i| Vec3::from(self.vertices[i as usize].position));
            let n = (b - a).cross(c - a); // length = 2 * area: area weighting for free
            for &i in tri {
                acc[i as usize] += n;
            }
        }
        for (v, n) in self.vertices.iter_mut().zip(acc) {
            v.normal = n.try_normalize().unwrap_or(Vec3::Y).to_array();
        }
    }

    /// Makes every normal unit length (zero or non-finite normals become +Y).
    pub fn normalize_normals(&mut self) {
        for v in &mut self.vertices {
            v.normal = Vec3::from(v.normal).try_normalize().unwrap_or(Vec3::Y).to_array();
        }
    }

    /// Sets the tangents from an attribute array (glTF `TANGENT`). Each is made unit length
    /// with a handedness of exactly ±1; a zero, non-finite or missing one becomes all zero
    /// (no tangent frame at that vertex).
    pub fn set_tangents(&mut self, tangents: &[Vec4]) {
        for (i, v) in self.vertices.iter_mut().enumerate() {
            v.tangent = tangents.get(i).map_or([0.0; 4], |t| sanitize_tangent(*t));
        }
    }

    /// Generates tangents from positions, normals and uvs, in bounded time and stack whatever
    /// the mesh's topology, and says how.
    ///
    /// MikkTSpace (`bevy_mikktspace`, as Blender, Substance and the glTF sample models' bakers
    /// use, and as the glTF specification asks) is used when its cost on this mesh is bounded:
    /// its work grows with the square of the triangles around one vertex, on one edge or of
    /// the corners at one position, and its grouping recurses once per triangle around a
    /// vertex, so a fan of 100 000 triangles or one triangle repeated 200 000 times would take
    /// minutes or overflow the stack. Those costs are estimated from the mesh first
    /// (O(n log n), see [`tangents::work_limit`]), and when the recursion is deep MikkTSpace
    /// runs on a thread whose stack fits it. Vertices MikkTSpace gives no frame (only
    /// degenerate triangles touch them) get all-zero tangents.
    ///
    /// Otherwise (and for non-finite or out-of-range data) the tangents are per-vertex UV
    /// derivatives (Lengyel's method) in O(n): each triangle's derivatives of position along u
    /// and v, weighted by its UV area, summed at its vertices, made orthogonal to the normal,
    /// handedness from the v derivative, all zero where there is no usable frame. They match
    /// MikkTSpace's on planar, linearly mapped surfaces, are close on smooth ones, and differ
    /// where uv seams, mirrored islands or degenerate triangles meet a vertex. The result
    /// says which was used, and why.
    #[must_use = "the tangents may come from the fallback, which the caller should report"]
    pub fn generate_tangents(&mut self) -> TangentMethod {
        for v in &mut self.vertices {
            v.tangent = [0.0; 4];
        }
        let fallback = match tangents::plan(self) {
            Ok(plan) => match tangents::run_mikktspace(self, &plan) {
                Ok(()) => return TangentMethod::MikkTSpace,
                Err(why) => why,
            },
            Err(why) => why,
        };
        tangents::uv_derivative_tangents(self);
        TangentMethod::UvDerivatives(fallback)
    }

    /// True when at least one vertex has a tangent frame.
    pub fn has_tangents(&self) -> bool {
        self.vertices.iter().any(|v| v.tangent[3] != 0.0)
    }

    /// Object-space bounds.
    pub fn bounds(&self) -> Aabb {
        let mut b = Aabb::EMPTY;
        for v in &self.vertices {
            b.extend(Vec3::from(v.position));
        }
        b
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }
}

/// A unit tangent with handedness ±1, or all zero when `t` has no usable direction.
fn sanitize_tangent(t: Vec4) -> [f32; 4] {
    match t.truncate().try_normalize() {
        Some(dir) if t.w.is_finite() => dir.extend(if t.w < 0.0 { -1.0 } else { 1.0 }).to_array(),
        _ => [0.0; 4],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn generated_normals_point_out_of_a_ccw_triangle() {
        let m = MeshData::from_attributes("tri", &[Vec3::ZERO, Vec3::X, Vec3::Y], None, None, None).unwrap();
        for v in &m.vertices {
            assert_eq!(v.normal, [0.0, 0.0, 1.0]);
        }
    }

    #[test]
    fn out_of_range_index_is_an_error() {
        let e = MeshData::from_attributes("bad", &[Vec3::ZERO; 3], None, None, Some(vec![0, 1, 7]));
        assert_eq!(e, Err(MeshError::IndexOutOfRange { index: 7, at: 2, vertices: 3 }));
    }

    /// A quad in the xy plane with u along +x and v along -y (glTF's uv origin is top-left):
    /// MikkTSpace gives tangent +x and a handedness with `w * cross(n, t)` along +v (-y);
    /// mirrored uvs (u along -x) flip the tangent and the handedness.
    #[test]
    fn generated_tangents_follow_u_and_flip_when_mirrored() {
        let positions = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        let uvs = [Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0), Vec2::new(1.0, 0.0), Vec2::new(0.0, 0.0)];
        let indices = Some(vec![0, 1, 2, 0, 2, 3]);
        let mut m = MeshData::from_attributes("quad", &positions, None, Some(&uvs), indices.clone()).unwrap();
        assert_eq!(m.generate_tangents(), TangentMethod::MikkTSpace);
        for v in &m.vertices {
            let t = Vec4::from(v.tangent);
            assert!((t - Vec4::new(1.0, 0.0, 0.0, -1.0)).abs().max_element() < 1e-5, "{t}");
        }
        let mirrored = uvs.map(|uv| Vec2::new(1.0 - uv.x, uv.y));
        let mut m =
            MeshData::from_attributes("mirrored", &positions, None, Some(&mirrored), indices).unwrap();
        assert_eq!(m.generate_tangents(), TangentMethod::MikkTSpace);
        for v in &m.vertices {
            let t = Vec4::from(v.tangent);
            assert!((t - Vec4::new(-1.0, 0.0, 0.0, 1.0)).abs().max_element() < 1e-5, "{t}");
        }
    }

    #[test]
    fn unusable_tangents_become_zero() {
        let mut m =
            MeshData::from_attributes("tri", &[Vec3::ZERO, Vec3::X, Vec3::Y], None, None, None).unwrap();
        m.set_tangents(&[Vec4::new(0.0, 0.0, 0.0, 1.0), Vec4::new(2.0, 0.0, 0.0, 0.5), Vec4::NAN]);
        assert_eq!(m.vertices[0].tangent, [0.0; 4]);
        assert_eq!(m.vertices[1].tangent, [1.0, 0.0, 0.0, 1.0]);
        assert_eq!(m.vertices[2].tangent, [0.0; 4]);
        // Degenerate uvs (all zero) give no frame, not NaN.
        assert_eq!(m.generate_tangents(), TangentMethod::MikkTSpace);
        assert!(m.vertices.iter().all(|v| v.tangent.iter().all(|x| x.is_finite())));
    }

    #[test]
    fn degenerate_triangles_give_finite_normals() {
        let m = MeshData::from_attributes("deg", &[Vec3::ZERO; 3], None, None, None).unwrap();
        assert!(m.vertices.iter().all(|v| v.normal.iter().all(|x| x.is_finite())));
    }
}
