//! The page's URL query parameters, parsed into typed options: an unknown name, a repeated
//! name or a bad value is an error naming the parameter, shown on the page.

use manylight::app::cli::{parse_debug_view, parse_on_off, parse_pipeline, parse_size};
use manylight::prelude::*;
use manylight::render::DebugViewMode;
use percent_encoding::percent_decode_str;

/// Animated lights in the demo's rig by default.
pub const DEFAULT_LIGHTS: usize = 1024;

/// The scenes the page can show.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum WebScene {
    /// The embedded hall (six warm lights of its own) with a rig of animated lights.
    Hall,
    /// The sphere-shell stress scene: still lights on a sphere around the camera.
    SphereShell,
    /// A glTF file under the site's `assets/` folder, fetched by the page, with a rig of
    /// animated lights around it.
    Gltf(AssetPath),
}

impl WebScene {
    /// The built-in scenes, in the order the error message lists them.
    pub const BUILT_IN: [WebScene; 2] = [WebScene::Hall, WebScene::SphereShell];

    /// The value the `scene` parameter takes for it.
    pub fn name(&self) -> &str {
        match self {
            WebScene::Hall => "hall",
            WebScene::SphereShell => "sphere-shell",
            WebScene::Gltf(path) => path.as_str(),
        }
    }
}

/// The path of a `.gltf` or `.glb` file under the site's `assets/` folder: `/`-separated
/// names of letters, digits, `-`, `_` and `.`, none of them `.` or `..`, so the URL the page
/// fetches it from (`assets/` + the path) stays in that folder.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct AssetPath(String);

impl AssetPath {
    /// The folder, relative to the page, that glTF files are fetched from.
    pub const FOLDER: &'static str = "assets/";

    /// `path` if it names a `.gltf` or `.glb` file inside [`AssetPath::FOLDER`].
    pub fn parse(path: &str) -> Result<AssetPath, String> {
        let lower = path.to_ascii_lowercase();
        if !(lower.ends_with(".gltf") || lower.ends_with(".glb")) {
            return Err("expected hall, sphere-shell, or a .gltf or .glb file under assets/ \
                 (such as DamagedHelmet/DamagedHelmet.glb)"
                .into());
        }
        for part in path.split('/') {
            let plain = part.chars().all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c));
            if part.is_empty() || part == "." || part == ".." || !plain {
                return Err(format!(
                    "`{part}` is not a plain file or folder name (letters, digits, `-`, `_`, `.`): \
                     the file must lie under assets/"
                ));
            }
        }
        Ok(AssetPath(path.to_owned()))
    }

    /// The path as given (under [`AssetPath::FOLDER`]).
    pub fn as_str(&self) -> &str {
        &self.0
    }

    /// The URL the page fetches the file from, relative to the page.
    pub fn url(&self) -> String {
        format!("{}{}", AssetPath::FOLDER, self.0)
    }
}

/// How the page's clock advances.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WebClock {
    /// Wall time, as a window runs.
    Wall,
    /// 1/60 s an update, as headless rendering runs: frame `n` shows the same instant as the
    /// native renderer's frame `n` (the image tests compare them).
    Fixed,
}

/// How frames reach the page's canvas.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WebPresent {
    /// A WebGPU canvas presents each frame, with the egui overlay drawn over it.
    Canvas,
    /// Each frame is rendered offscreen, read back without a wait and drawn into a 2D canvas
    /// (no overlay): for browsers whose WebGPU canvas cannot present, such as headless
    /// Chromium on SwiftShader.
    ReadBack,
}

/// Which GPU API the page renders with (the `backend` parameter).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WebBackend {
    /// WebGPU when `navigator.gpu` gives an adapter, otherwise WebGL2.
    Auto,
    /// WebGPU only: without an adapter the page shows the error.
    WebGpu,
    /// WebGL2: clustered forward with CPU-built light lists in textures
    /// (`manylight::render::texture_lists`), shown through read-back.
    WebGl2,
}

impl WebBackend {
    /// The value the `backend` parameter takes for it.
    pub fn name(self) -> &'static str {
        match self {
            WebBackend::Auto => "auto",
            WebBackend::WebGpu => "webgpu",
            WebBackend::WebGl2 => "webgl2",
        }
    }
}

/// What the page renders, from its URL query.
#[derive(Clone, Debug, PartialEq)]
pub struct WebOptions {
    /// `lights`: lights of the rig (hall) or on the shell (sphere-shell). Default 1024.
    pub lights: usize,
    /// `pipeline`: the many-light pipeline. Default: the renderer's default.
    pub pipeline: PipelineKind,
    /// `shadows`: `on` makes every light cast. Default off.
    pub shadows: bool,
    /// `debug-view`: a debug view instead of the image. Default none.
    pub debug_view: DebugViewMode,
    /// `scene`: `hall` (default), `sphere-shell`, or a `.gltf`/`.glb` file under `assets/`.
    pub scene: WebScene,
    /// `size`: `WxH` fixes the canvas size; by default the canvas fills the page.
    pub size: Option<UVec2>,
    /// `overlay`: `off` hides the egui overlay. Default on.
    pub overlay: bool,
    /// `clock`: `fixed` steps 1/60 s an update; default `wall`.
    pub clock: WebClock,
    /// `capture`: the update whose image is read back (from 1), for `manylight.capture()`.
    pub capture: Option<u64>,
    /// `present`: `canvas` (default) or `read-back`. WebGL2 always shows its frames through
    /// read-back.
    pub present: WebPresent,
    /// `backend`: `auto` (default: WebGPU where the browser gives an adapter, else WebGL2),
    /// `webgpu` or `webgl2`.
    pub backend: WebBackend,
}

impl Default for WebOptions {
    fn default() -> Self {
        WebOptions {
            lights: DEFAULT_LIGHTS,
            pipeline: PipelineKind::default(),
            shadows: false,
            debug_view: DebugViewMode::None,
            scene: WebScene::Hall,
            size: None,
            overlay: true,
            clock: WebClock::Wall,
            capture: None,
            present: WebPresent::Canvas,
            backend: WebBackend::Auto,
        }
    }
}

/// A URL query the page cannot run with.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ParamError {
    /// A name the page does not take.
    #[error("unknown URL parameter `{name}` (known: {})", KNOWN.join(", "))]
    Unknown {
        /// The name as given.
        name: String,
    },
    /// A name given twice.
    #[error("URL parameter `{name}` is given more than once")]
    Repeated {
        /// The name.
        name: String,
    },
    /// A value the parameter does not take.
    #[error("URL parameter `{name}={value}`: {reason}")]
    Invalid {
        /// The name.
        name: &'static str,
        /// The value as given.
        value: String,
        /// What is wrong with it, and what is expected.
        reason: String,
    },
}

/// The parameters the page takes.
const KNOWN: [&str; 11] = [
    "lights",
    "pipeline",
    "shadows",
    "debug-view",
    "scene",
    "size",
    "overlay",
    "clock",
    "capture",
    "present",
    "backend",
];

impl WebOptions {
    /// Parses a URL query (`location.search`, with or without its leading `?`).
    pub fn from_query(query: &str) -> Result<WebOptions, ParamError> {
        let mut options = WebOptions::default();
        let mut seen: Vec<&'static str> = Vec::new();
        for pair in query.trim_start_matches('?').split('&').filter(|p| !p.is_empty()) {
            let (raw_name, raw_value) = pair.split_once('=').unwrap_or((pair, ""));
            let name = decode(raw_name);
            let value = decode(raw_value);
            let Some(&known) = KNOWN.iter().find(|k| **k == name) else {
                return Err(ParamError::Unknown { name });
            };
            if seen.contains(&known) {
                return Err(ParamError::Repeated { name });
            }
            seen.push(known);
            options.set(known, &value).map_err(|reason| ParamError::Invalid {
                name: known,
                value,
                reason,
            })?;
        }
        Ok(options)
    }

    fn set(&mut self, name: &'static str, value: &str) -> Result<(), String> {
        match name {
            "lights" => {
                let n: usize = value.parse().map_err(|_| "expected a whole number of lights".to_string())?;
                manylight::math::light_count::check_app_lights(n).map_err(|e| e.to_string())?;
                self.lights = n;
            }
            "pipeline" => self.pipeline = parse_pipeline(value)?,
            "shadows" => self.shadows = parse_on_off(value)?,
            "debug-view" => self.debug_view = parse_debug_view(value)?,
            "scene" => {
                self.scene = match WebScene::BUILT_IN.into_iter().find(|s| s.name() == value) {
                    Some(scene) => scene,
                    None => WebScene::Gltf(AssetPath::parse(value)?),
                };
            }
            "size" => self.size = Some(parse_size(value)?),
            "overlay" => self.overlay = parse_on_off(value)?,
            "clock" => {
                self.clock = match value {
                    "wall" => WebClock::Wall,
                    "fixed" => WebClock::Fixed,
                    _ => return Err("expected wall or fixed".into()),
                }
            }
            "present" => {
                self.present = match value {
                    "canvas" => WebPresent::Canvas,
                    "read-back" => WebPresent::ReadBack,
                    _ => return Err("expected canvas or read-back".into()),
                }
            }
            "backend" => {
                self.backend = [WebBackend::Auto, WebBackend::WebGpu, WebBackend::WebGl2]
                    .into_iter()
                    .find(|b| b.name() == value)
                    .ok_or("expected auto, webgpu or webgl2")?;
            }
            "capture" => match value.parse::<u64>() {
                Ok(n) if n >= 1 => self.capture = Some(n),
                _ => return Err("expected the number of an update, from 1".into()),
            },
            _ => unreachable!("`{name}` is in KNOWN"),
        }
        Ok(())
    }
}

/// A query component with `+` as space and `%XX` escapes decoded (invalid UTF-8 replaced).
fn decode(s: &str) -> String {
    percent_decode_str(&s.replace('+', " ")).decode_utf8_lossy().into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_without_a_query() {
        assert_eq!(WebOptions::from_query("").unwrap(), WebOptions::default());
        assert_eq!(WebOptions::from_query("?").unwrap(), WebOptions::default());
    }

    #[test]
    fn every_parameter_parses() {
        let o = WebOptions::from_query(
            "?lights=100000&pipeline=clustered-deferred&shadows=on&debug-view=light-count&scene=sphere-shell&size=128x96&overlay=off&clock=fixed&capture=3&present=read-back&backend=webgl2",
        )
        .unwrap();
        assert_eq!(o.lights, 100_000);
        assert_eq!(o.pipeline, PipelineKind::ClusteredDeferred);
        assert!(o.shadows);
        assert_eq!(o.debug_view, DebugViewMode::LightCount);
        assert_eq!(o.scene, WebScene::SphereShell);
        assert_eq!(o.size, Some(UVec2::new(128, 96)));
        assert!(!o.overlay);
        assert_eq!(o.clock, WebClock::Fixed);
        assert_eq!(o.capture, Some(3));
        assert_eq!(o.present, WebPresent::ReadBack);
        assert_eq!(o.backend, WebBackend::WebGl2);
        assert_eq!(WebOptions::from_query("backend=webgpu").unwrap().backend, WebBackend::WebGpu);
        assert_eq!(WebOptions::from_query("backend=auto").unwrap().backend, WebBackend::Auto);
    }

    #[test]
    fn a_gltf_scene_is_a_file_under_assets() {
        let o = WebOptions::from_query("scene=DamagedHelmet/DamagedHelmet.glb").unwrap();
        let WebScene::Gltf(path) = &o.scene else { panic!("{:?}", o.scene) };
        assert_eq!(path.url(), "assets/DamagedHelmet/DamagedHelmet.glb");
        assert_eq!(o.scene.name(), "DamagedHelmet/DamagedHelmet.glb");
    }

    #[test]
    fn escapes_are_decoded() {
        assert_eq!(WebOptions::from_query("scene=sphere%2Dshell").unwrap().scene, WebScene::SphereShell);
    }

    #[test]
    fn bad_queries_name_the_parameter() {
        let cases = [
            ("lihgts=5", "unknown URL parameter `lihgts`"),
            ("lights=5&lights=6", "`lights` is given more than once"),
            ("lights=-1", "`lights=-1`"),
            ("lights=99999999999", "`lights=99999999999`"),
            ("pipeline=fast", "`pipeline=fast`: unknown pipeline"),
            ("shadows=yes", "`shadows=yes`"),
            ("scene=moon", "expected hall, sphere-shell, or a .gltf or .glb file under assets/"),
            ("scene=../secret.glb", "`..` is not a plain file or folder name"),
            ("scene=/etc/x.gltf", "`` is not a plain file or folder name"),
            ("scene=https://example.com/x.glb", "`https:` is not a plain file or folder name"),
            ("scene=a//b.glb", "`` is not a plain file or folder name"),
            ("size=0x0", "`size=0x0`"),
            ("capture=0", "`capture=0`"),
            ("clock=slow", "expected wall or fixed"),
            ("present=screen", "expected canvas or read-back"),
            ("backend=webgl", "`backend=webgl`: expected auto, webgpu or webgl2"),
            ("debug-view=%FF", "`debug-view=\u{FFFD}`"),
        ];
        for (query, expected) in cases {
            let message = WebOptions::from_query(query).unwrap_err().to_string();
            assert!(message.contains(expected), "{query}: {message}");
        }
    }
}
