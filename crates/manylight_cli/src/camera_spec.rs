//! The `--camera` value of `render`: the scene's own camera, a fitted one, one of the file's
//! cameras by index, or an explicit placement (`look-at:…` for perspective, `ortho:…` for
//! orthographic), so a render can match a reference image's framing.

use glam::Vec3;
use manylight_core::{Aabb, Projection};
use manylight_scene::{SceneCamera, camera_looking_at};
use std::fmt;

/// The accepted forms, for error messages.
const FORMS: &str =
    "scene, fit, an index, look-at:EX,EY,EZ:TX,TY,TZ:FOV_DEG or ortho:EX,EY,EZ:TX,TY,TZ:HEIGHT";

/// Where `render` takes its camera from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum CameraSpec {
    /// The file's first camera, else a fitted one.
    Scene,
    /// A camera that frames the whole scene from the front.
    Fit,
    /// One of the file's cameras.
    Index(usize),
    /// A perspective camera at `eye` looking at `target` (+Y up), `fov_y_deg` degrees tall.
    LookAt {
        /// Camera position in world space.
        eye: Vec3,
        /// Point the camera looks at.
        target: Vec3,
        /// Vertical field of view in degrees, in (0, 180).
        fov_y_deg: f32,
    },
    /// An orthographic camera at `eye` looking at `target` (+Y up), `height` world units tall.
    Ortho {
        /// Camera position in world space.
        eye: Vec3,
        /// Point the camera looks at.
        target: Vec3,
        /// Visible height in world units (> 0).
        height: f32,
    },
}

/// Why a `--camera` value was rejected; each names the part that is wrong.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum CameraSpecError {
    /// Neither a keyword, an index nor one of the explicit forms.
    Unknown(String),
    /// An explicit form without exactly three `:`-separated parts after its keyword.
    Parts {
        /// `look-at` or `ortho`.
        form: &'static str,
        /// How many parts came after the keyword.
        found: usize,
    },
    /// A point that is not three finite comma-separated numbers.
    Point {
        /// `eye` or `target`.
        which: &'static str,
        /// The text given for it.
        text: String,
    },
    /// The eye and the target are the same point: there is no view direction.
    SamePoint,
    /// A field of view that is not a number strictly between 0 and 180 degrees.
    Fov(String),
    /// An orthographic height that is not a finite number above 0.
    Height(String),
}

impl fmt::Display for CameraSpecError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Unknown(s) => write!(f, "--camera `{s}`: expected {FORMS}"),
            Self::Parts { form, found } => write!(
                f,
                "--camera {form}: expected 3 `:`-separated parts after `{form}:` (eye, target and {}), found {found}",
                if *form == "ortho" { "height" } else { "field of view" }
            ),
            Self::Point { which, text } => {
                write!(f, "--camera: {which} `{text}` is not three finite numbers X,Y,Z")
            }
            Self::SamePoint => write!(f, "--camera: the eye and the target are the same point"),
            Self::Fov(s) => write!(f, "--camera: field of view `{s}` is not a number of degrees in (0, 180)"),
            Self::Height(s) => {
                write!(f, "--camera: orthographic height `{s}` is not a finite number above 0")
            }
        }
    }
}

impl std::error::Error for CameraSpecError {}

impl std::str::FromStr for CameraSpec {
    type Err = CameraSpecError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "scene" => return Ok(Self::Scene),
            "fit" => return Ok(Self::Fit),
            _ => {}
        }
        if let Ok(i) = s.parse::<usize>() {
            return Ok(Self::Index(i));
        }
        let (form, rest) = match s.split_once(':') {
            Some(("look-at", rest)) => ("look-at", rest),
            Some(("ortho", rest)) => ("ortho", rest),
            _ => return Err(CameraSpecError::Unknown(s.to_string())),
        };
        let parts: Vec<&str> = rest.split(':').collect();
        let [eye, target, last] = parts[..] else {
            return Err(CameraSpecError::Parts { form, found: parts.len() });
        };
        let eye = parse_point("eye", eye)?;
        let target = parse_point("target", target)?;
        if eye == target {
            return Err(CameraSpecError::SamePoint);
        }
        let number = last.trim().parse::<f32>().ok().filter(|x| x.is_finite());
        if form == "ortho" {
            let height =
                number.filter(|h| *h > 0.0).ok_or_else(|| CameraSpecError::Height(last.to_string()))?;
            Ok(Self::Ortho { eye, target, height })
        } else {
            let fov_y_deg = number
                .filter(|d| *d > 0.0 && *d < 180.0)
                .ok_or_else(|| CameraSpecError::Fov(last.to_string()))?;
            Ok(Self::LookAt { eye, target, fov_y_deg })
        }
    }
}

/// Three finite comma-separated numbers.
fn parse_point(which: &'static str, text: &str) -> Result<Vec3, CameraSpecError> {
    let bad = || CameraSpecError::Point { which, text: text.to_string() };
    let coords: Vec<f32> = text
        .split(',')
        .map(|c| c.trim().parse::<f32>().ok().filter(|x| x.is_finite()))
        .collect::<Option<_>>()
        .ok_or_else(bad)?;
    match coords[..] {
        [x, y, z] => Ok(Vec3::new(x, y, z)),
        _ => Err(bad()),
    }
}

impl CameraSpec {
    /// The camera of an explicit form (`None` for the others), with near and far planes that
    /// enclose `bounds` (the scene's) as seen from the eye, so a scene of any scale keeps its
    /// depth precision.
    pub(crate) fn explicit_camera(&self, bounds: Aabb) -> Option<SceneCamera> {
        let (eye, target) = match *self {
            Self::LookAt { eye, target, .. } | Self::Ortho { eye, target, .. } => (eye, target),
            Self::Scene | Self::Fit | Self::Index(_) => return None,
        };
        let (center, radius) = if bounds.is_empty() || !bounds.min.is_finite() || !bounds.max.is_finite() {
            (target, 1.0)
        } else {
            (bounds.center(), (bounds.size().length() * 0.5).max(1e-6))
        };
        let distance = eye.distance(center);
        // Half the nearest possible distance of the geometry, or a small fraction of the
        // distance when the eye is inside the bounds; twice the farthest as the far plane.
        let near = (distance - radius).max(distance * 1e-3).max(radius * 1e-4) * 0.5;
        let far = (distance + radius) * 2.0;
        let projection = match *self {
            Self::Ortho { height, .. } => Projection::orthographic(height, near, far),
            Self::LookAt { fov_y_deg, .. } => Projection::perspective(fov_y_deg.to_radians(), near, far),
            Self::Scene | Self::Fit | Self::Index(_) => return None,
        };
        Some(SceneCamera { transform: camera_looking_at(eye, target), projection })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use manylight_core::ProjectionKind;

    fn parse(s: &str) -> Result<CameraSpec, CameraSpecError> {
        s.parse()
    }

    #[test]
    fn keywords_and_indices() {
        assert_eq!(parse("scene"), Ok(CameraSpec::Scene));
        assert_eq!(parse("fit"), Ok(CameraSpec::Fit));
        assert_eq!(parse("2"), Ok(CameraSpec::Index(2)));
        assert_eq!(parse("front"), Err(CameraSpecError::Unknown("front".into())));
        assert_eq!(parse("-1"), Err(CameraSpecError::Unknown("-1".into())));
    }

    #[test]
    fn look_at_and_ortho() {
        assert_eq!(
            parse("look-at:0,0,5:0,0.5,0:45"),
            Ok(CameraSpec::LookAt {
                eye: Vec3::new(0.0, 0.0, 5.0),
                target: Vec3::new(0.0, 0.5, 0.0),
                fov_y_deg: 45.0
            })
        );
        assert_eq!(
            parse("ortho:1, 2, 3:0,0,0:0.5"),
            Ok(CameraSpec::Ortho { eye: Vec3::new(1.0, 2.0, 3.0), target: Vec3::ZERO, height: 0.5 })
        );
    }

    #[test]
    fn errors_name_the_bad_part() {
        assert_eq!(parse("look-at:0,0,5:0,0,0"), Err(CameraSpecError::Parts { form: "look-at", found: 2 }));
        assert_eq!(parse("ortho:0,0,5:0,0,0:1:2"), Err(CameraSpecError::Parts { form: "ortho", found: 4 }));
        assert_eq!(
            parse("look-at:0,0:0,0,0:45"),
            Err(CameraSpecError::Point { which: "eye", text: "0,0".into() })
        );
        assert_eq!(
            parse("look-at:0,0,5:0,nan,0:45"),
            Err(CameraSpecError::Point { which: "target", text: "0,nan,0".into() })
        );
        assert_eq!(parse("look-at:1,1,1:1,1,1:45"), Err(CameraSpecError::SamePoint));
        assert_eq!(parse("look-at:0,0,5:0,0,0:180"), Err(CameraSpecError::Fov("180".into())));
        assert_eq!(parse("look-at:0,0,5:0,0,0:wide"), Err(CameraSpecError::Fov("wide".into())));
        assert_eq!(parse("ortho:0,0,5:0,0,0:0"), Err(CameraSpecError::Height("0".into())));
        assert_eq!(parse("ortho:0,0,5:0,0,0:inf"), Err(CameraSpecError::Height("inf".into())));
        assert!(parse("ortho:0,0,5:0,0,0:-1").unwrap_err().to_string().contains("orthographic height `-1`"));
    }

    #[test]
    fn explicit_cameras_enclose_the_bounds() {
        let bounds = Aabb { min: Vec3::splat(-1.0), max: Vec3::splat(1.0) };
        let cam = parse("look-at:0,0,10:0,0,0:30").unwrap().explicit_camera(bounds).unwrap();
        assert_eq!(cam.transform.w_axis.truncate(), Vec3::new(0.0, 0.0, 10.0));
        // The camera looks down its local -Z, towards the target.
        assert!(cam.transform.transform_vector3(-Vec3::Z).abs_diff_eq(-Vec3::Z, 1e-6));
        assert!((cam.projection.fov_y - 30f32.to_radians()).abs() < 1e-6);
        let radius = 3f32.sqrt();
        assert!(cam.projection.near > 0.0 && cam.projection.near < 10.0 - radius);
        assert!(cam.projection.far > 10.0 + radius);
        let ortho = parse("ortho:0,0,10:0,0,0:2").unwrap().explicit_camera(bounds).unwrap();
        assert_eq!(ortho.projection.kind, ProjectionKind::Orthographic { height: 2.0 });
        assert_eq!(CameraSpec::Fit.explicit_camera(bounds), None);
    }
}
