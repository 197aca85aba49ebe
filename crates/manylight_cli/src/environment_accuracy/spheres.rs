//! The test scene: two rows of spheres (metal above, dielectric below) of rising roughness,
//! seen by an orthographic camera, and where each pixel's ray meets them, cast analytically
//! as the GPU's finely tessellated sphere mesh is seen.

use glam::{UVec2, Vec2, Vec3};
use manylight_core::Projection;
use manylight_core::environment::PbrSurface;
use manylight_scene::shapes::SphereGrid;
use manylight_scene::{Scene, SceneCamera, camera_looking_at};

/// Perceptual roughness of each column, left to right.
pub const ROUGHNESS: [f32; 5] = [0.05, 0.25, 0.5, 0.75, 1.0];

/// Each row's name and metalness, top to bottom.
pub const ROWS: [(&str, f32); 2] = [("metal", 1.0), ("dielectric", 0.0)];

/// Linear base colour of every sphere.
pub const ALBEDO: Vec3 = Vec3::new(0.9, 0.7, 0.5);

/// Sphere radius; the centres are one unit apart.
const RADIUS: f32 = 0.46;

/// Where the camera stands, looking at the grid's centre along -Z.
const EYE: Vec3 = Vec3::new(0.0, 0.0, 10.0);

/// Rings and segments of the sphere mesh: its outline is within 0.01 pixel of the circle at
/// the default size, and its interpolated normals within 0.02° of the sphere's.
const RINGS: u32 = 64;
const SEGMENTS: u32 = 128;

/// A pixel whose centre's ray meets a sphere at least one pixel inside its outline.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Row-major pixel index.
    pub pixel: usize,
    /// Index into [`ROWS`].
    pub row: usize,
    /// Index into [`ROUGHNESS`].
    pub column: usize,
    /// Unit surface normal.
    pub normal: Vec3,
    /// Unit direction towards the eye.
    pub view: Vec3,
}

impl Hit {
    /// The sphere's material.
    pub fn surface(&self) -> PbrSurface {
        PbrSurface { albedo: ALBEDO, metallic: ROWS[self.row].1, roughness: ROUGHNESS[self.column] }
    }
}

/// The grid for an image of `size`: the camera, the scene the GPU draws and the pixels the
/// measurement keeps.
pub struct Spheres {
    /// Image size.
    pub size: UVec2,
    /// The camera's projection (orthographic).
    pub projection: Projection,
    /// The pixels that see a sphere away from its outline, in pixel order.
    pub hits: Vec<Hit>,
    /// Pixels that see a sphere at all (outline band included).
    pub covered: usize,
}

/// The grid: [`ROWS`] by [`ROUGHNESS`], centres one unit apart about the origin.
fn grid() -> SphereGrid {
    SphereGrid {
        radius: RADIUS,
        rings: RINGS,
        segments: SEGMENTS,
        albedo: ALBEDO,
        metallic: ROWS.iter().map(|(_, m)| *m).collect(),
        roughness: ROUGHNESS.to_vec(),
    }
}

impl Spheres {
    /// The grid seen in an image of `size`, every sphere in view.
    pub fn new(size: UVec2) -> Spheres {
        let aspect = size.x as f32 / size.y.max(1) as f32;
        // Two rows and five columns of unit cells, whichever bounds the view.
        let height = 2.0f32.max(ROUGHNESS.len() as f32 / aspect);
        let projection = Projection::orthographic(height, 0.1, 20.0);
        let mut spheres = Spheres { size, projection, hits: Vec::new(), covered: 0 };
        spheres.cast();
        spheres
    }

    /// The scene the GPU draws: the spheres and the camera, no light.
    pub fn scene(&self) -> Scene {
        let mut scene = grid().scene("environment spheres");
        scene
            .cameras
            .push(SceneCamera { transform: camera_looking_at(EYE, Vec3::ZERO), projection: self.projection });
        scene
    }

    /// Casts each pixel centre's ray (as the rasteriser samples it: NDC from the pixel centre,
    /// y up) and keeps the hits at least one pixel inside a sphere's outline, where the mesh
    /// and the sphere agree.
    fn cast(&mut self) {
        let (w, h) = (self.size.x as usize, self.size.y as usize);
        let aspect = w as f32 / h.max(1) as f32;
        let half = self.projection.orthographic_half_extent(aspect).unwrap_or(Vec2::ONE);
        let pixel = 2.0 * half.y / h.max(1) as f32;
        let world_from_view = camera_looking_at(EYE, Vec3::ZERO);
        let right = world_from_view.transform_vector3(Vec3::X).normalize();
        let up = world_from_view.transform_vector3(Vec3::Y).normalize();
        let forward = world_from_view.transform_vector3(Vec3::NEG_Z).normalize();
        let grid = grid();
        for y in 0..h {
            for x in 0..w {
                let ndc = Vec2::new(
                    (x as f32 + 0.5) / w as f32 * 2.0 - 1.0,
                    1.0 - (y as f32 + 0.5) / h as f32 * 2.0,
                );
                let origin = EYE + right * ndc.x * half.x + up * ndc.y * half.y;
                for (row, column) in (0..ROWS.len()).flat_map(|r| (0..ROUGHNESS.len()).map(move |c| (r, c))) {
                    let oc = origin - grid.centre(row, column);
                    let b = oc.dot(forward);
                    // Squared distance between the ray and the centre.
                    let d2 = oc.length_squared() - b * b;
                    if d2 > RADIUS * RADIUS {
                        continue;
                    }
                    self.covered += 1;
                    if d2.sqrt() > RADIUS - pixel {
                        break;
                    }
                    let t = -b - (RADIUS * RADIUS - d2).sqrt();
                    let normal = (origin + forward * t - grid.centre(row, column)).normalize();
                    self.hits.push(Hit { pixel: y * w + x, row, column, normal, view: -forward });
                    break;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_sphere_is_seen_and_its_outline_left_out() {
        let spheres = Spheres::new(UVec2::new(320, 128));
        for row in 0..ROWS.len() {
            for column in 0..ROUGHNESS.len() {
                let n = spheres.hits.iter().filter(|h| h.row == row && h.column == column).count();
                // Radius 29.4 pixels less the one-pixel band: about pi 28.4^2 pixels.
                assert!((2400..2600).contains(&n), "sphere ({row}, {column}): {n} pixels");
            }
        }
        let grazing = spheres.hits.iter().map(|h| h.normal.dot(h.view)).fold(1.0f32, f32::min);
        assert!((0.2..0.35).contains(&grazing), "smallest n.v {grazing}");
        assert!(spheres.covered > spheres.hits.len());
    }
}
