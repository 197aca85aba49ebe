//! Whole-scene operations: bounds, a fallback camera, validation, and loading by spec.

use crate::{LoadOptions, Scene, SceneCamera, SceneError, default_scene, load_gltf, sphere_shell_scene};
use glam::{Mat4, Vec3};
use manylight_core::{Aabb, Projection};
use std::path::{Path, PathBuf};

/// Loads a scene by spec: `"default"` (the embedded hall), `"sphere-shell"` (the light-shell
/// stress scene) or a path to a `.gltf`/`.glb` file.
pub fn load_scene(spec: &str, options: &LoadOptions) -> Result<Scene, SceneError> {
    match spec {
        "default" => Ok(default_scene()),
        "sphere-shell" => Ok(sphere_shell_scene()),
        _ => {
            let path = Path::new(spec);
            let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
            let is_gltf = matches!(ext.as_deref(), Some("gltf" | "glb"));
            if !is_gltf && !path.is_file() {
                return Err(SceneError::UnknownSpec { path: PathBuf::from(spec) });
            }
            load_gltf(path, options)
        }
    }
}

/// World-from-camera transform of a camera at `eye` looking at `target` (local -Z forward,
/// +Y as close to world up as possible).
pub fn camera_looking_at(eye: Vec3, target: Vec3) -> Mat4 {
    let back = (eye - target).try_normalize().unwrap_or(Vec3::Z);
    let right = Vec3::Y.cross(back).try_normalize().unwrap_or(Vec3::X);
    let up = back.cross(right);
    Mat4::from_cols(right.extend(0.0), up.extend(0.0), back.extend(0.0), eye.extend(1.0))
}

impl Scene {
    /// World-space bounds of all instances ([`Aabb::EMPTY`] for a scene without geometry).
    pub fn bounds(&self) -> Aabb {
        let local: Vec<Aabb> = self.meshes.iter().map(|m| m.bounds()).collect();
        let mut out = Aabb::EMPTY;
        for inst in &self.instances {
            if let Some(b) = local.get(inst.mesh) {
                let world = b.transformed(&inst.transform);
                if !world.is_empty() {
                    out = out.union(&world);
                }
            }
        }
        out
    }

    /// The scene's first camera, or else one that frames [`Scene::bounds`] from the front
    /// (looking down -Z, as glTF viewers show a model) for a viewport of aspect ratio `aspect`.
    pub fn camera_or_fit(&self, aspect: f32) -> SceneCamera {
        if let Some(c) = self.cameras.first() {
            return *c;
        }
        let fov_y = 60f32.to_radians();
        let bounds = self.bounds();
        let (center, radius) = if bounds.is_empty() || !bounds.min.is_finite() || !bounds.max.is_finite() {
            (Vec3::ZERO, 1.0)
        } else {
            (bounds.center(), (bounds.size().length() * 0.5).max(1e-3))
        };
        let aspect = if aspect.is_finite() && aspect > 0.0 { aspect } else { 1.0 };
        // The bounding sphere fits when its angular radius is half the narrower field of view.
        let half_x = ((fov_y * 0.5).tan() * aspect).atan();
        let half = (fov_y * 0.5).min(half_x);
        let distance = radius / half.sin();
        // From the front, as glTF viewers frame a model: +Z is the asset's front.
        let dir = Vec3::Z;
        let eye = center + dir * distance;
        let transform = camera_looking_at(eye, center);
        SceneCamera {
            transform,
            projection: Projection::perspective(
                fov_y,
                (distance - radius).max(distance * 1e-3).max(1e-4) * 0.5,
                (distance + radius) * 2.0,
            ),
        }
    }

    /// Sets the anisotropic filtering of every texture of every material (1 = off; see
    /// [`TextureSampler::anisotropy_clamp`](manylight_core::TextureSampler::anisotropy_clamp)).
    pub fn set_anisotropy(&mut self, clamp: u16) {
        for material in &mut self.materials {
            for t in std::sync::Arc::make_mut(material).texture_slots_mut().into_iter().flatten() {
                t.sampler.anisotropy_clamp = clamp;
            }
        }
    }

    /// Checks that every index is in range and every number is usable (finite transforms,
    /// non-negative light and emissive parameters, valid meshes with finite tangents, every
    /// texture with the right byte count).
    pub fn validate(&self) -> Result<(), SceneError> {
        let invalid = |problem: String| SceneError::Invalid { path: PathBuf::from(&self.name), problem };
        for (i, m) in self.meshes.iter().enumerate() {
            m.validate().map_err(|e| invalid(format!("mesh {i} (`{}`): {e}", m.label)))?;
            if let Some(v) = m.vertices.iter().position(|v| !v.tangent.iter().all(|x| x.is_finite())) {
                return Err(invalid(format!(
                    "mesh {i} (`{}`): vertex {v} has a non-finite tangent",
                    m.label
                )));
            }
        }
        for (i, m) in self.materials.iter().enumerate() {
            let emissive = m.emissive_rgb();
            let finite = m.base_color_linear().is_finite()
                && m.shininess.is_finite()
                && m.specular.is_finite()
                && m.normal_scale.is_finite()
                && m.occlusion_strength.is_finite()
                && emissive.is_finite()
                && emissive.min_element() >= 0.0;
            if !finite {
                return Err(invalid(format!("material {i} has non-finite or negative parameters")));
            }
            for t in m.textures() {
                if !(t.uv_transform.matrix2.is_finite() && t.uv_transform.translation.is_finite()) {
                    return Err(invalid(format!(
                        "material {i} texture `{}` has a non-finite uv transform",
                        t.image.label
                    )));
                }
                let t = &t.image;
                let expected = t.width as u64 * t.height as u64 * 4;
                if t.width == 0 || t.height == 0 || t.rgba8.len() as u64 != expected {
                    return Err(invalid(format!(
                        "material {i} texture `{}` is {}x{} with {} bytes",
                        t.label,
                        t.width,
                        t.height,
                        t.rgba8.len()
                    )));
                }
            }
        }
        for (i, inst) in self.instances.iter().enumerate() {
            if inst.mesh >= self.meshes.len() || inst.material >= self.materials.len() {
                return Err(invalid(format!("instance {i} refers to a missing mesh or material")));
            }
            if !inst.transform.is_finite() {
                return Err(invalid(format!("instance {i} has a non-finite transform")));
            }
        }
        for (i, l) in self.lights.iter().enumerate() {
            let ok = l.position.is_finite()
                && l.color.is_finite()
                && l.color.min_element() >= 0.0
                && l.intensity.is_finite()
                && l.intensity >= 0.0
                && l.radius.is_finite()
                && l.radius >= 0.0;
            if !ok {
                return Err(invalid(format!("light {i} has non-finite or negative parameters")));
            }
        }
        for (i, c) in self.cameras.iter().enumerate() {
            let p = c.projection;
            if !c.transform.is_finite() || p.sanitized() != p {
                return Err(invalid(format!("camera {i} has an unusable transform or projection")));
            }
        }
        self.validate_nodes().map_err(invalid)
    }

    /// The node tree: parents first, finite local transforms, and every instance, light and
    /// camera hanging from at most one node.
    fn validate_nodes(&self) -> Result<(), String> {
        let mut owned = [
            vec![false; self.instances.len()],
            vec![false; self.lights.len()],
            vec![false; self.cameras.len()],
        ];
        for (i, n) in self.nodes.iter().enumerate() {
            if n.parent.is_some_and(|p| p >= i) {
                return Err(format!("node {i} comes before its parent"));
            }
            if !n.local.is_finite() {
                return Err(format!("node {i} has a non-finite transform"));
            }
            let lists = [("instance", &n.instances), ("light", &n.lights), ("camera", &n.cameras)];
            for ((kind, list), flags) in lists.into_iter().zip(&mut owned) {
                for &k in list {
                    match flags.get_mut(k) {
                        Some(flag) if !*flag => *flag = true,
                        Some(_) => return Err(format!("{kind} {k} hangs from two nodes")),
                        None => return Err(format!("node {i} refers to a missing {kind} {k}")),
                    }
                }
            }
        }
        Ok(())
    }
}
