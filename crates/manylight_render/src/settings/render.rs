//! What a frame is rendered with: the [`RenderSettings`] an app sets, and the
//! [`FrameSettings`] a view draws with (those settings and its debug view).

use super::{ClusterSettings, DebugViewMode, EnvironmentFilter, GBufferLayout, PipelineKind, ShadowSettings};
use manylight_core::ShadingModel;
use manylight_core::codec::NormalCodec;

/// How frames are rendered. With the `bevy` feature it is a resource: the app's
/// `RenderSettings` is this type, so a new setting is added here only. Changes apply from the
/// next frame.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "bevy", derive(bevy_ecs::prelude::Resource))]
pub struct RenderSettings {
    /// The many-light pipeline.
    pub pipeline: PipelineKind,
    /// The shading model for materials that do not choose one.
    pub shading: ShadingModel,
    /// Multiplier applied before tone mapping, for cameras without an [`Exposure`](super::Exposure).
    pub exposure: f32,
    /// Constant ambient term (fraction of albedo).
    pub ambient: f32,
    /// Colour the HDR target is cleared to (linear RGB).
    pub clear_color: [f32; 3],
    /// Cluster grid, culling test, optional cap and depth pre-pass of the tiled and clustered
    /// pipelines.
    pub clusters: ClusterSettings,
    /// G-buffer layout of the deferred pipelines.
    pub gbuffer: GBufferLayout,
    /// Normal encoding of the `Packed` and `Compact` G-buffer layouts.
    pub normal_codec: NormalCodec,
    /// Shadow atlas and face sizes, and whether casting lights cast.
    pub shadows: ShadowSettings,
    /// How finely the cameras' environments are prefiltered.
    pub environment_filter: EnvironmentFilter,
}

impl RenderSettings {
    /// Refuses values no frame can be rendered with, naming the field: an `exposure` that is
    /// not finite and positive (NaN would give an all-black image with no non-finite pixel
    /// counted), an `ambient` or a `clear_color` channel that is not finite and non-negative.
    pub fn check_values(&self) -> Result<(), String> {
        if !(self.exposure.is_finite() && self.exposure > 0.0) {
            return Err(format!("exposure {} must be finite and positive", self.exposure));
        }
        if !(self.ambient.is_finite() && self.ambient >= 0.0) {
            return Err(format!("ambient {} must be finite and non-negative", self.ambient));
        }
        if !self.clear_color.iter().all(|c| c.is_finite() && *c >= 0.0) {
            return Err(format!("clear_color {:?} must be finite and non-negative", self.clear_color));
        }
        self.shadows.check_values()?;
        self.environment_filter.check_values()
    }
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            pipeline: PipelineKind::ClusteredForward,
            shading: ShadingModel::Pbr,
            exposure: 1.0,
            ambient: 0.03,
            clear_color: [0.005, 0.006, 0.01],
            clusters: ClusterSettings::default(),
            gbuffer: GBufferLayout::Full,
            normal_codec: NormalCodec::Octa16,
            shadows: ShadowSettings::default(),
            environment_filter: EnvironmentFilter::default(),
        }
    }
}

/// What a view is rendered with: the [`RenderSettings`] and the debug view (the app's
/// `DebugView` resource, or a camera's `CameraDebugView`). Reads of the render settings go
/// through `Deref` (`settings.pipeline`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameSettings {
    /// The render settings.
    pub render: RenderSettings,
    /// Debug view (replaces tone mapping when not `None`).
    pub debug_view: DebugViewMode,
    /// Light count shown as the hottest colour of the light-count heatmap.
    pub debug_heatmap_max: u32,
}

impl Default for FrameSettings {
    fn default() -> Self {
        FrameSettings::from(RenderSettings::default())
    }
}

impl From<RenderSettings> for FrameSettings {
    /// `render` without a debug view.
    fn from(render: RenderSettings) -> Self {
        FrameSettings { render, debug_view: DebugViewMode::None, debug_heatmap_max: 32 }
    }
}

impl std::ops::Deref for FrameSettings {
    type Target = RenderSettings;
    fn deref(&self) -> &RenderSettings {
        &self.render
    }
}

impl std::ops::DerefMut for FrameSettings {
    fn deref_mut(&mut self) -> &mut RenderSettings {
        &mut self.render
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An exposure of NaN would render an all-black frame with no non-finite pixel counted:
    /// values no frame can render with are refused, naming the field.
    #[test]
    fn settings_no_frame_can_render_with_are_refused_by_name() {
        assert_eq!(RenderSettings::default().check_values(), Ok(()));
        let cases = [
            (RenderSettings { exposure: f32::NAN, ..Default::default() }, "exposure"),
            (RenderSettings { exposure: 0.0, ..Default::default() }, "exposure"),
            (RenderSettings { exposure: f32::INFINITY, ..Default::default() }, "exposure"),
            (RenderSettings { ambient: -0.1, ..Default::default() }, "ambient"),
            (RenderSettings { ambient: f32::NAN, ..Default::default() }, "ambient"),
            (RenderSettings { clear_color: [0.0, f32::INFINITY, 0.0], ..Default::default() }, "clear_color"),
        ];
        for (settings, field) in cases {
            let message = settings.check_values().expect_err(field);
            assert!(message.starts_with(field), "{message}");
        }
    }
}
