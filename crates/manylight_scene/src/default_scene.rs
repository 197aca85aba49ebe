//! The embedded default scene: a procedural Sponza-like hall that needs no files.
//!
//! Layout (metres, +Y up, the hall runs along X):
//! 1. a 40 × 16 floor at y = 0, side walls at z = ±8 and end walls at x = ±20, 12 high;
//! 2. two arcades (z = ±4) of 8 columns each (base, shaft, capital), semicircular arches
//!    between neighbouring columns and a beam on top;
//! 3. an upper gallery floor over each side aisle with a row of smaller columns, a top beam
//!    and coloured cloth banners hanging between them;
//! 4. spheres and boxes in the nave, 6 warm lights down its centre, and a camera at the
//!    west end at head height looking east.

use crate::shapes::{arch, cuboid, cylinder, uv_sphere};
use crate::textures::{bricks, cloth, floor_tiles, stone};
use crate::{Scene, SceneCamera, SceneInstance, SceneLight, camera_looking_at};
use glam::{Mat4, Vec3};
use manylight_core::{Color, MaterialData, MaterialTexture, MeshData, Projection, ShadingModel, TextureData};
use std::sync::Arc;

/// Half length (X) and half width (Z) of the hall.
const HALF_LENGTH: f32 = 20.0;
const HALF_WIDTH: f32 = 8.0;
/// Wall height.
const WALL_HEIGHT: f32 = 12.0;
/// Columns per arcade, their spacing and the arcades' distance from the centre line.
const COLUMNS: usize = 8;
const COLUMN_SPACING: f32 = 5.0;
const ARCADE_Z: f32 = 4.0;
/// Height of the top of the lower capitals, where the arches spring.
const SPRING_Y: f32 = 6.0;
/// Height of the top of the gallery floor.
const GALLERY_Y: f32 = 9.0;

/// Collects meshes, materials and instances.
struct Assembler {
    scene: Scene,
}

impl Assembler {
    fn mesh(&mut self, m: MeshData) -> usize {
        self.scene.meshes.push(Arc::new(m));
        self.scene.meshes.len() - 1
    }

    fn material(
        &mut self,
        label: &str,
        color: Vec3,
        tex: Option<&Arc<TextureData>>,
        (metallic, roughness): (f32, f32),
        (shininess, specular): (f32, f32),
    ) -> usize {
        self.scene.materials.push(Arc::new(MaterialData {
            label: format!("default_scene/{label}"),
            base_color: Color::linear_rgb(color.x, color.y, color.z),
            base_color_texture: tex.cloned().map(MaterialTexture::new),
            metallic,
            roughness,
            metallic_roughness_texture: None,
            shading: None,
            shininess,
            specular,
            ..MaterialData::default()
        }));
        self.scene.materials.len() - 1
    }

    fn place(&mut self, mesh: usize, material: usize, transform: Mat4) {
        self.scene.instances.push(SceneInstance { mesh, material, transform });
    }
}

/// X of column `i` of an arcade.
fn column_x(i: usize) -> f32 {
    (i as f32 - (COLUMNS as f32 - 1.0) * 0.5) * COLUMN_SPACING
}

/// The embedded procedural hall (about 100 instances, a few thousand triangles), lit by six
/// static warm lights, with one camera looking down the hall. Deterministic.
pub fn default_scene() -> Scene {
    let mut a = Assembler { scene: Scene { name: "default".into(), ..Scene::default() } };
    let m = add_materials(&mut a);
    add_shell(&mut a, &m);
    add_arcades(&mut a, &m);
    add_props(&mut a, &m);
    add_lights(&mut a);
    add_camera(&mut a);
    a.scene
}

/// The hall's materials, by the part they dress (indices into the scene's materials).
struct Materials {
    floor: usize,
    wall: usize,
    stone: usize,
    arch: usize,
    /// Banner colours, cycled through.
    cloth: [usize; 3],
    gold: usize,
    plaster: usize,
    teal: usize,
    crate_box: usize,
}

/// Adds the textures and materials every part of the hall uses.
fn add_materials(a: &mut Assembler) -> Materials {
    let [tiles, brick, stone_tex, cloth_tex] =
        [floor_tiles(256), bricks(256), stone(128), cloth(128)].map(Arc::new);
    let floor = a.material("floor", Vec3::ONE, Some(&tiles), (0.0, 0.35), (64.0, 0.3));
    let wall = a.material("wall", Vec3::ONE, Some(&brick), (0.0, 0.85), (8.0, 0.05));
    let stone = a.material("stone", Vec3::ONE, Some(&stone_tex), (0.0, 0.7), (16.0, 0.1));
    let arch = a.material("arch", Vec3::new(1.0, 0.9, 0.8), Some(&stone_tex), (0.0, 0.7), (16.0, 0.1));
    let cloth = [
        a.material("cloth_red", Vec3::new(0.75, 0.08, 0.06), Some(&cloth_tex), (0.0, 0.95), (4.0, 0.02)),
        a.material("cloth_green", Vec3::new(0.08, 0.55, 0.15), Some(&cloth_tex), (0.0, 0.95), (4.0, 0.02)),
        a.material("cloth_blue", Vec3::new(0.08, 0.15, 0.7), Some(&cloth_tex), (0.0, 0.95), (4.0, 0.02)),
    ];
    let gold = a.material("gold", Vec3::new(1.0, 0.76, 0.33), None, (1.0, 0.3), (128.0, 0.9));
    let plaster = a.material("plaster", Vec3::splat(0.9), None, (0.0, 0.6), (32.0, 0.2));
    let teal = a.material("teal", Vec3::new(0.1, 0.6, 0.6), None, (0.0, 0.2), (256.0, 0.5));
    // Matte boxes use the Lambert model so one surface type ignores the global setting.
    let crate_box = a.material("crate", Vec3::new(0.6, 0.45, 0.3), None, (0.0, 1.0), (1.0, 0.0));
    if let Some(m) = Arc::get_mut(&mut a.scene.materials[crate_box]) {
        m.shading = Some(ShadingModel::Lambert);
    }
    Materials { floor, wall, stone, arch, cloth, gold, plaster, teal, crate_box }
}

/// Adds the shell: floor, side walls, end walls.
fn add_shell(a: &mut Assembler, m: &Materials) {
    let t = Mat4::from_translation;
    let floor = a.mesh(cuboid("floor", Vec3::new(2.0 * HALF_LENGTH, 0.2, 2.0 * HALF_WIDTH), 0.25));
    a.place(floor, m.floor, t(Vec3::new(0.0, -0.1, 0.0)));
    let side = a.mesh(cuboid("side_wall", Vec3::new(2.0 * HALF_LENGTH, WALL_HEIGHT, 0.5), 0.25));
    let end = a.mesh(cuboid("end_wall", Vec3::new(0.5, WALL_HEIGHT, 2.0 * HALF_WIDTH + 0.5), 0.25));
    for s in [-1.0, 1.0] {
        a.place(side, m.wall, t(Vec3::new(0.0, WALL_HEIGHT * 0.5, s * (HALF_WIDTH + 0.25))));
        a.place(end, m.wall, t(Vec3::new(s * (HALF_LENGTH + 0.25), WALL_HEIGHT * 0.5, 0.0)));
    }
}

/// Adds both arcades and the galleries above them.
fn add_arcades(a: &mut Assembler, m: &Materials) {
    let t = Mat4::from_translation;
    // Lower arcades: base, shaft, capital; arches between columns; a beam on top.
    let base = a.mesh(cuboid("column_base", Vec3::new(1.2, 0.4, 1.2), 0.5));
    let shaft = a.mesh(cylinder("column_shaft", 0.4, 5.3, 16, 0.5));
    let capital = a.mesh(cuboid("column_capital", Vec3::new(1.1, 0.3, 1.1), 0.5));
    let arch_mesh = a.mesh(arch("arch", 2.1, 2.5, 0.8, 12, 0.5));
    let beam = a.mesh(cuboid("arcade_beam", Vec3::new(2.0 * HALF_LENGTH, 0.5, 0.9), 0.5));
    // Upper gallery: floor slab over each aisle, small columns, top beam, banners.
    let gallery = a.mesh(cuboid(
        "gallery_floor",
        Vec3::new(2.0 * HALF_LENGTH, 0.3, HALF_WIDTH - ARCADE_Z + 0.45),
        0.25,
    ));
    let small_shaft = a.mesh(cylinder("gallery_column", 0.25, 2.6, 12, 0.5));
    let banner = a.mesh(cuboid("banner", Vec3::new(3.2, 2.2, 0.05), 0.5));
    for s in [-1.0f32, 1.0] {
        let z = s * ARCADE_Z;
        for i in 0..COLUMNS {
            let x = column_x(i);
            a.place(base, m.stone, t(Vec3::new(x, 0.2, z)));
            a.place(shaft, m.stone, t(Vec3::new(x, 0.4 + 2.65, z)));
            a.place(capital, m.stone, t(Vec3::new(x, SPRING_Y - 0.15, z)));
            a.place(small_shaft, m.stone, t(Vec3::new(x, GALLERY_Y + 1.3, z)));
            if i + 1 < COLUMNS {
                let mid = x + COLUMN_SPACING * 0.5;
                a.place(arch_mesh, m.arch, t(Vec3::new(mid, SPRING_Y, z)));
                // Banners hang in every other upper bay, cycling through the cloth colours.
                if i % 2 == 0 {
                    let cloth = m.cloth[(i / 2 + if s > 0.0 { 1 } else { 0 }) % m.cloth.len()];
                    a.place(banner, cloth, t(Vec3::new(mid, GALLERY_Y + 1.4, z - s * 0.3)));
                }
            }
        }
        a.place(beam, m.stone, t(Vec3::new(0.0, SPRING_Y + 2.5 + 0.25, z)));
        let gz = s * (ARCADE_Z + (HALF_WIDTH - ARCADE_Z + 0.45) * 0.5 - 0.45);
        a.place(gallery, m.stone, t(Vec3::new(0.0, GALLERY_Y - 0.15, gz)));
        a.place(beam, m.stone, t(Vec3::new(0.0, GALLERY_Y + 2.6 + 0.25, z)));
    }
}

/// Adds the props in the nave: three spheres and four crates.
fn add_props(a: &mut Assembler, m: &Materials) {
    let sphere = a.mesh(uv_sphere("sphere", 1.0, 16, 32, false));
    for (x, r, material) in [(-10.0, 1.0, m.gold), (0.0, 0.7, m.plaster), (10.0, 1.2, m.teal)] {
        a.place(
            sphere,
            material,
            Mat4::from_scale_rotation_translation(
                Vec3::splat(r),
                glam::Quat::IDENTITY,
                Vec3::new(x, r, -1.0),
            ),
        );
    }
    let unit_box = a.mesh(cuboid("crate", Vec3::ONE, 1.0));
    for (i, (x, z, size)) in
        [(-6.0, 1.5, 1.2), (-5.0, 2.2, 0.7), (5.0, -1.8, 1.0), (14.0, 1.0, 1.5)].into_iter().enumerate()
    {
        let rot = glam::Quat::from_rotation_y(0.3 * i as f32);
        a.place(
            unit_box,
            m.crate_box,
            Mat4::from_scale_rotation_translation(Vec3::splat(size), rot, Vec3::new(x, size * 0.5, z)),
        );
    }
}

/// Adds six warm lights down the nave, enough to see the hall with no extra lights (80 cd: the
/// PBR model's diffuse lobe is albedo / pi, so this lights the hall as 25 did under Lambert).
fn add_lights(a: &mut Assembler) {
    for i in 0..6 {
        a.scene.lights.push(SceneLight {
            position: Vec3::new(-15.0 + 6.0 * i as f32, 4.0, 0.0),
            color: Vec3::new(1.0, 0.78, 0.5),
            intensity: 80.0,
            radius: 15.0,
            shape: manylight_core::LightShape::Point,
        });
    }
}

/// Adds the camera at the west end at head height, looking east down the nave.
fn add_camera(a: &mut Assembler) {
    let eye = Vec3::new(-HALF_LENGTH + 2.0, 1.7, 0.0);
    a.scene.cameras.push(SceneCamera {
        transform: camera_looking_at(eye, eye + Vec3::X),
        projection: Projection::perspective(60f32.to_radians(), 0.1, 200.0),
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_scene_is_valid_and_modest() {
        let s = default_scene();
        s.validate().expect("valid");
        assert!(s.instances.len() > 20);
        let tris: usize = s.instances.iter().map(|i| s.meshes[i.mesh].triangle_count()).sum();
        assert!(tris < 50_000, "{tris} triangles");
        let b = s.bounds();
        assert!(b.min.is_finite() && b.max.is_finite());
        assert!((4..=8).contains(&s.lights.len()));
        assert_eq!(s.cameras.len(), 1);
    }
}
