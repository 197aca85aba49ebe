//! The manylight web demo: the embedded hall lit by a thousand animated lights in a browser
//! canvas, on WebGPU, or on WebGL2 where the browser has no WebGPU adapter. `scripts/web.sh`
//! builds it with wasm-bindgen and serves `web/index.html`.
//!
//! The page contract (for people and tests):
//! - URL query parameters ([`options::WebOptions`]): `lights`, `pipeline`, `shadows`,
//!   `debug-view`, `scene` (`hall` or `sphere-shell`), `size`, `overlay`, `clock`, `capture`,
//!   `present` (`canvas` or `read-back`), `backend` (`auto`, `webgpu` or `webgl2`: without a
//!   WebGPU adapter `auto` falls back to WebGL2, [`webgl`]).
//!   A bad one shows its error on the page.
//! - The camera: drag to look, W/A/S/D or the arrows to move, Q/E down and up, Shift faster
//!   ([`controls`]).
//! - After the first frame `document.title` is `manylight: ready`.
//! - `manylight.stats()`: the last frame's statistics, the document of
//!   `manylight render --stats-json` plus `backend` (`webgpu` or `webgl2`).
//! - `manylight.error()`: the first error, or `undefined`.
//! - `manylight.capture()`: the image of the update `capture` names, as a PNG data URL, once
//!   read back.
#![warn(missing_docs)]

pub mod controls;
pub mod demo;
pub mod options;
#[cfg(target_arch = "wasm32")]
pub mod page;
pub mod readback_canvas;
pub mod webgl;
