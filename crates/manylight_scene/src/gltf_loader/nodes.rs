//! The node tree of a glTF scene: transforms, mesh instances, point lights and cameras.

use super::Ctx;
use crate::{SceneCamera, SceneError, SceneInstance, SceneLight};
use glam::{Mat4, Quat, Vec3};
use gltf::json::camera::Type as CameraType;
use gltf::json::extensions::scene::khr_lights_punctual::Type as LightType;
use gltf::json::mesh::{Mode, Semantic};
use gltf::json::validation::Checked;
use manylight_core::{MeshData, Projection, radius_for_intensity};
use std::sync::Arc;

impl Ctx<'_> {
    /// Walks the default scene (or scene 0, or every root node when there is no scene) and
    /// adds instances, lights and cameras for each node.
    pub(super) fn walk_scene(&mut self) -> Result<(), SceneError> {
        let root = self.root;
        let roots: Vec<usize> = match (root.scene, root.scenes.first()) {
            (Some(s), _) => {
                let scene = self.lookup(&root.scenes, s.value(), "the default scene", "scene")?;
                scene.nodes.iter().map(|n| n.value()).collect()
            }
            (None, Some(scene)) => scene.nodes.iter().map(|n| n.value()).collect(),
            (None, None) => {
                let mut is_child = vec![false; root.nodes.len()];
                for n in &root.nodes {
                    for c in n.children.iter().flatten() {
                        if let Some(flag) = is_child.get_mut(c.value()) {
                            *flag = true;
                        }
                    }
                }
                (0..root.nodes.len()).filter(|&i| !is_child[i]).collect()
            }
        };
        let mut visited = vec![false; root.nodes.len()];
        let mut stack: Vec<(usize, Mat4, String)> =
            roots.into_iter().rev().map(|n| (n, Mat4::IDENTITY, "the scene".to_owned())).collect();
        while let Some((index, parent, referrer)) = stack.pop() {
            let node = self.lookup(&root.nodes, index, &referrer, "node")?;
            if std::mem::replace(&mut visited[index], true) {
                return Err(SceneError::NodeHierarchy { path: self.path.to_owned(), node: index });
            }
            let world = parent * self.local_transform(index)?;
            if !world.is_finite() {
                return Err(SceneError::NonFiniteTransform { path: self.path.to_owned(), node: index });
            }
            if let Some(mesh) = node.mesh {
                self.add_mesh_instances(index, mesh.value(), world)?;
            }
            if let Some(light) = node.extensions.as_ref().and_then(|e| e.khr_lights_punctual.as_ref()) {
                self.add_light(index, light.light.value(), world)?;
            }
            if let Some(camera) = node.camera {
                self.add_camera(index, camera.value(), world)?;
            }
            for child in node.children.iter().flatten().rev() {
                stack.push((child.value(), world, format!("node {index}")));
            }
        }
        Ok(())
    }

    /// The node's local transform (matrix, or translation * rotation * scale).
    fn local_transform(&self, index: usize) -> Result<Mat4, SceneError> {
        let node = &self.root.nodes[index];
        let non_finite = || SceneError::NonFiniteTransform { path: self.path.to_owned(), node: index };
        if let Some(m) = node.matrix {
            let m = Mat4::from_cols_array(&m);
            return if m.is_finite() { Ok(m) } else { Err(non_finite()) };
        }
        let t = Vec3::from_array(node.translation.unwrap_or([0.0; 3]));
        let s = Vec3::from_array(node.scale.unwrap_or([1.0; 3]));
        let r = node.rotation.as_ref().map_or(Quat::IDENTITY, |q| Quat::from_array(q.0));
        if !t.is_finite() || !s.is_finite() || !r.is_finite() {
            return Err(non_finite());
        }
        let r = if r.length_squared() > 1e-12 {
            r.normalize()
        } else {
            tracing::warn!(file = %self.path.display(), node = index, "zero rotation quaternion, using identity");
            Quat::IDENTITY
        };
        Ok(Mat4::from_scale_rotation_translation(s, r, t))
    }

    /// Adds one instance per triangle primitive of mesh `mesh`.
    fn add_mesh_instances(&mut self, node: usize, mesh: usize, world: Mat4) -> Result<(), SceneError> {
        let root = self.root;
        let m = self.lookup(&root.meshes, mesh, &format!("node {node}"), "mesh")?;
        for (p, prim) in m.primitives.iter().enumerate() {
            if prim.mode != Checked::Valid(Mode::Triangles) {
                tracing::warn!(
                    file = %self.path.display(), mesh, primitive = p,
                    "primitive mode is not TRIANGLES, skipped"
                );
                continue;
            }
            let Some(mesh_index) = self.primitive_mesh(mesh, p)? else { continue };
            let material = self.material_index(mesh, p, prim.material.map(|m| m.value()))?;
            self.scene.instances.push(SceneInstance { mesh: mesh_index, material, transform: world });
        }
        Ok(())
    }

    /// Scene mesh for primitive `p` of mesh `mesh`, converted once per accessor combination.
    /// `None` for primitives without positions or without triangles.
    fn primitive_mesh(&mut self, mesh: usize, p: usize) -> Result<Option<usize>, SceneError> {
        let root = self.root;
        let prim = &root.meshes[mesh].primitives[p];
        let what = format!("mesh {mesh} primitive {p}");
        let attr = |s: Semantic| prim.attributes.get(&Checked::Valid(s)).map(|a| a.value());
        let Some(pos) = attr(Semantic::Positions) else {
            tracing::warn!(file = %self.path.display(), mesh, primitive = p, "primitive has no POSITION, skipped");
            return Ok(None);
        };
        let key = [
            Some(pos),
            attr(Semantic::Normals),
            attr(Semantic::TexCoords(0)),
            prim.indices.map(|i| i.value()),
        ];
        if let Some(&index) = self.meshes.get(&key) {
            return Ok(Some(index));
        }
        let positions = self.read_vec3(pos, &what, "POSITION")?;
        let bad = |problem: String| SceneError::BadPrimitive {
            path: self.path.to_owned(),
            mesh,
            primitive: p,
            problem,
        };
        let mut normals = match key[1] {
            Some(a) => Some(self.read_vec3(a, &what, "NORMAL")?),
            None => None,
        };
        let mut uvs = match key[2] {
            Some(a) => Some(self.read_uv(a, &what)?),
            None => None,
        };
        let indices = match key[3] {
            Some(a) => Some(self.read_indices(a, &what)?),
            None => None,
        };
        if let Some(n) = &normals
            && n.len() != positions.len()
        {
            return Err(bad(format!("{} normals for {} positions", n.len(), positions.len())));
        }
        if let Some(u) = &uvs
            && u.len() != positions.len()
        {
            return Err(bad(format!("{} TEXCOORD_0 values for {} positions", u.len(), positions.len())));
        }
        // Broken normals or uvs are repaired (they only shade wrong); broken positions are errors.
        if let Some(n) = normals.as_mut().filter(|n| n.iter().any(|v| !v.is_finite())) {
            tracing::warn!(file = %self.path.display(), mesh, primitive = p, "non-finite normals replaced");
            n.iter_mut().filter(|v| !v.is_finite()).for_each(|v| *v = Vec3::ZERO);
        }
        if let Some(u) = uvs.as_mut().filter(|u| u.iter().any(|v| !v.is_finite())) {
            tracing::warn!(file = %self.path.display(), mesh, primitive = p, "non-finite TEXCOORD_0 replaced");
            u.iter_mut().filter(|v| !v.is_finite()).for_each(|v| *v = glam::Vec2::ZERO);
        }
        let count = indices.as_ref().map_or(positions.len(), Vec::len);
        if count == 0 {
            tracing::warn!(file = %self.path.display(), mesh, primitive = p, "primitive has no triangles, skipped");
            return Ok(None);
        }
        let label = match &root.meshes[mesh].name {
            Some(name) => format!("{name}/{p}"),
            None => format!("{} mesh {mesh}/{p}", self.file_name()),
        };
        let data = MeshData::from_attributes(label, &positions, normals.as_deref(), uvs.as_deref(), indices)
            .map_err(|source| SceneError::Mesh { path: self.path.to_owned(), mesh, primitive: p, source })?;
        self.scene.meshes.push(Arc::new(data));
        let index = self.scene.meshes.len() - 1;
        self.meshes.insert(key, index);
        Ok(Some(index))
    }

    /// Scene material index for glTF material `material` (`None`: the default material).
    fn material_index(
        &mut self,
        mesh: usize,
        p: usize,
        material: Option<usize>,
    ) -> Result<usize, SceneError> {
        if let Some(&i) = self.materials.get(&material) {
            return Ok(i);
        }
        let data = match material {
            Some(m) => {
                self.lookup(&self.root.materials, m, &format!("mesh {mesh} primitive {p}"), "material")?;
                self.material(m)?
            }
            None => manylight_core::MaterialData::default(),
        };
        self.scene.materials.push(Arc::new(data));
        let i = self.scene.materials.len() - 1;
        self.materials.insert(material, i);
        Ok(i)
    }

    /// Adds `KHR_lights_punctual` light `light` at the node's world position (point lights only).
    fn add_light(&mut self, node: usize, light: usize, world: Mat4) -> Result<(), SceneError> {
        let lights = (self.root.extensions.as_ref())
            .and_then(|e| e.khr_lights_punctual.as_ref())
            .map_or(&[][..], |k| &k.lights[..]);
        let l = self.lookup(lights, light, &format!("node {node}"), "light")?;
        let bad = |problem: String| SceneError::BadLight { path: self.path.to_owned(), light, problem };
        match l.type_ {
            Checked::Valid(LightType::Point) => {}
            Checked::Valid(other) => {
                tracing::warn!(file = %self.path.display(), light, "{other:?} lights are not supported, skipped");
                return Ok(());
            }
            Checked::Invalid => return Err(bad("invalid light type".into())),
        }
        let color = Vec3::from_array(l.color);
        if !color.is_finite() || color.min_element() < 0.0 {
            return Err(bad(format!("color {:?} must be finite and non-negative", l.color)));
        }
        if !l.intensity.is_finite() || l.intensity < 0.0 {
            return Err(bad(format!("intensity {} must be finite and non-negative", l.intensity)));
        }
        let radius = match l.range {
            Some(r) if r.is_finite() && r > 0.0 => r,
            Some(r) => return Err(bad(format!("range {r} must be finite and positive"))),
            None => radius_for_intensity(l.intensity * color.max_element(), 0.01),
        };
        self.scene.lights.push(SceneLight {
            position: world.transform_point3(Vec3::ZERO),
            color,
            intensity: l.intensity,
            radius,
        });
        Ok(())
    }

    /// Adds perspective camera `camera` with the node's world transform (scale removed).
    fn add_camera(&mut self, node: usize, camera: usize, world: Mat4) -> Result<(), SceneError> {
        let root = self.root;
        let c = self.lookup(&root.cameras, camera, &format!("node {node}"), "camera")?;
        let bad = |problem: &str| SceneError::BadCamera {
            path: self.path.to_owned(),
            camera,
            problem: problem.into(),
        };
        match (&c.type_, &c.perspective) {
            (Checked::Valid(CameraType::Perspective), Some(p)) => {
                if !(p.yfov.is_finite() && p.yfov > 0.0 && p.yfov < std::f32::consts::PI) {
                    return Err(bad("yfov must be in (0, pi)"));
                }
                if !(p.znear.is_finite() && p.znear > 0.0) {
                    return Err(bad("znear must be finite and positive"));
                }
                let far = match p.zfar {
                    None => p.znear * 1e4,
                    Some(f) if f.is_finite() && f > p.znear => f,
                    Some(_) => return Err(bad("zfar must be finite and greater than znear")),
                };
                let (_, rotation, translation) = world.to_scale_rotation_translation();
                let transform = Mat4::from_rotation_translation(rotation.normalize(), translation);
                if !transform.is_finite() {
                    return Err(bad(&format!("node {node} gives it a degenerate transform")));
                }
                self.scene.cameras.push(SceneCamera {
                    transform,
                    projection: Projection { fov_y: p.yfov, near: p.znear, far }.sanitized(),
                });
            }
            (Checked::Valid(CameraType::Perspective), None) => {
                return Err(bad("perspective camera without perspective parameters"));
            }
            _ => tracing::warn!(file = %self.path.display(), camera, "non-perspective camera skipped"),
        }
        Ok(())
    }
}
