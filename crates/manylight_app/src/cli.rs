//! Command-line value parsers shared by the `manylight` CLI and the examples (for clap's
//! `value_parser`): each names the accepted values in its error.

use glam::{UVec2, UVec3};
use manylight_core::ShadingModel;
use manylight_core::cluster::{CullTest, MAX_GRID_DIM, ZSlicing};
use manylight_core::codec::NormalCodec;
use manylight_render::{BloomChain, DebugViewMode, GBufferLayout, PipelineKind};

/// The value of `all` whose `name` is `s`, or an error listing every name.
fn named<T: Copy>(what: &str, s: &str, all: &[T], name: impl Fn(T) -> &'static str) -> Result<T, String> {
    all.iter().copied().find(|&v| name(v) == s).ok_or_else(|| {
        let names: Vec<_> = all.iter().map(|&v| name(v)).collect();
        format!("unknown {what} `{s}` (expected one of: {})", names.join(", "))
    })
}

/// `naive`, `forward-plus`, `clustered-forward`, `clustered-deferred`, `tiled-deferred` or
/// `light-volumes`.
pub fn parse_pipeline(s: &str) -> Result<PipelineKind, String> {
    named("pipeline", s, &PipelineKind::ALL, PipelineKind::name)
}

/// `pbr`, `lambert`, `blinn-phong` or `toon`.
pub fn parse_shading(s: &str) -> Result<ShadingModel, String> {
    named("shading model", s, &ShadingModel::ALL, ShadingModel::name)
}

/// `full`, `packed` or `compact`.
pub fn parse_gbuffer(s: &str) -> Result<GBufferLayout, String> {
    named("G-buffer layout", s, &GBufferLayout::ALL, GBufferLayout::name)
}

/// `xyz`, `spherical`, `octa16` or `octa8`.
pub fn parse_normal_codec(s: &str) -> Result<NormalCodec, String> {
    named("normal codec", s, &NormalCodec::ALL, NormalCodec::name)
}

/// `on` or `off`.
pub fn parse_on_off(s: &str) -> Result<bool, String> {
    match s {
        "on" => Ok(true),
        "off" => Ok(false),
        _ => Err(format!("`{s}`: expected on or off")),
    }
}

/// What `--shadows` asks for: no shadow, shadow maps (`on` or `maps`) or shadow rays.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ShadowChoice {
    /// No light casts.
    #[default]
    Off,
    /// Every light casts, into shadow maps ([`manylight_render::ShadowMethod::Maps`]).
    Maps,
    /// Every light casts, found with rays ([`manylight_render::ShadowMethod::Rays`]).
    Rays,
}

impl ShadowChoice {
    /// True when lights cast.
    pub fn casts(self) -> bool {
        self != ShadowChoice::Off
    }

    /// How shadows are found (maps when off: nothing casts then).
    pub fn method(self) -> manylight_render::ShadowMethod {
        match self {
            ShadowChoice::Rays => manylight_render::ShadowMethod::Rays,
            ShadowChoice::Off | ShadowChoice::Maps => manylight_render::ShadowMethod::Maps,
        }
    }

    /// The name `--shadows` takes (`maps` for `on`).
    pub fn name(self) -> &'static str {
        match self {
            ShadowChoice::Off => "off",
            ShadowChoice::Maps => "maps",
            ShadowChoice::Rays => "rays",
        }
    }
}

/// `off`, `on` (shadow maps, as before maps and rays were told apart), `maps` or `rays`.
pub fn parse_shadows(s: &str) -> Result<ShadowChoice, String> {
    if s == "on" {
        return Ok(ShadowChoice::Maps);
    }
    named(
        "shadow setting",
        s,
        &[ShadowChoice::Off, ShadowChoice::Maps, ShadowChoice::Rays],
        ShadowChoice::name,
    )
    .map_err(|e| e.replace("(expected one of: off,", "(expected one of: off, on,"))
}

/// `hardware2x2` or `gaussian`.
pub fn parse_shadow_filter(s: &str) -> Result<manylight_render::ShadowFilteringMethod, String> {
    named(
        "shadow filter",
        s,
        &manylight_render::ShadowFilteringMethod::ALL,
        manylight_render::ShadowFilteringMethod::name,
    )
}

/// Most shadow maps drawn again per frame (`ShadowSettings::max_redrawn_maps`): `None` for
/// every changed map.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RedrawBudget(pub Option<u32>);

/// A shadow map redraw budget: `all` (every changed map) or a count of at least 1.
pub fn parse_redraw_budget(s: &str) -> Result<RedrawBudget, String> {
    match s {
        "all" => Ok(RedrawBudget(None)),
        _ => match s.parse::<u32>() {
            Ok(n) if n >= 1 => Ok(RedrawBudget(Some(n))),
            _ => Err(format!("`{s}`: expected all or a count of maps of at least 1")),
        },
    }
}

/// `aabb`, `planes` or `both`.
pub fn parse_cull(s: &str) -> Result<CullTest, String> {
    named("culling test", s, &CullTest::ALL, CullTest::name)
}

/// `linear` or `exponential`.
pub fn parse_slicing(s: &str) -> Result<ZSlicing, String> {
    named("z slicing", s, &ZSlicing::ALL, ZSlicing::name)
}

/// A debug view name (`DebugViewMode::name`).
pub fn parse_debug_view(s: &str) -> Result<DebugViewMode, String> {
    named("debug view", s, &DebugViewMode::ALL, DebugViewMode::name)
}

/// `downsampled` or `full-resolution`.
pub fn parse_bloom_chain(s: &str) -> Result<BloomChain, String> {
    named("bloom chain", s, &[BloomChain::Downsampled, BloomChain::FullResolution], BloomChain::name)
}

/// `WxH`, each side in `1..=16384`.
pub fn parse_size(s: &str) -> Result<UVec2, String> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| format!("size `{s}` is not WxH"))?;
    let parse = |v: &str| v.trim().parse::<u32>().map_err(|e| format!("size `{s}`: {e}"));
    let (w, h) = (parse(w)?, parse(h)?);
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        return Err(format!("size `{s}`: each side must be in 1..=16384"));
    }
    Ok(UVec2::new(w, h))
}

/// A finite number in `range`, for the flag `what`.
fn finite_in(s: &str, what: &str, range: std::ops::RangeInclusive<f32>, rule: &str) -> Result<f32, String> {
    let v: f32 = s.trim().parse().map_err(|e| format!("{what} `{s}`: {e}"))?;
    if v.is_finite() && range.contains(&v) { Ok(v) } else { Err(format!("{what} `{s}`: must be {rule}")) }
}

/// An exposure multiplier: finite and positive.
pub fn parse_exposure(s: &str) -> Result<f32, String> {
    finite_in(s, "exposure", f32::MIN_POSITIVE..=f32::MAX, "a finite number above 0")
}

/// An exposure value at ISO 100: finite, in `-100..=100` (the range `Exposure::multiplier` keeps).
pub fn parse_ev100(s: &str) -> Result<f32, String> {
    finite_in(s, "ev100", -100.0..=100.0, "a finite number in -100..=100")
}

/// An ambient term (fraction of albedo): finite and non-negative.
pub fn parse_ambient(s: &str) -> Result<f32, String> {
    finite_in(s, "ambient", 0.0..=f32::MAX, "a finite number of at least 0")
}

/// `XxYxZ` cluster-grid dimensions, each in `1..=MAX_GRID_DIM`.
pub fn parse_grid(s: &str) -> Result<UVec3, String> {
    let parts: Vec<&str> = s.split(['x', 'X']).collect();
    let [x, y, z] = parts.as_slice() else {
        return Err(format!("grid `{s}` is not XxYxZ"));
    };
    let parse = |v: &str| v.trim().parse::<u32>().map_err(|e| format!("grid `{s}`: {e}"));
    let dims = UVec3::new(parse(x)?, parse(y)?, parse(z)?);
    if dims.min_element() == 0 || dims.max_element() > MAX_GRID_DIM {
        return Err(format!("grid `{s}`: each size must be in 1..={MAX_GRID_DIM}"));
    }
    Ok(dims)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exposure_and_ambient_refuse_non_finite_and_out_of_range_values() {
        for bad in ["NaN", "inf", "-inf", "0", "-1", "x"] {
            assert!(parse_exposure(bad).is_err(), "{bad}");
        }
        for bad in ["NaN", "inf", "101", "-100.5"] {
            assert!(parse_ev100(bad).is_err(), "{bad}");
        }
        for bad in ["NaN", "inf", "-0.1"] {
            assert!(parse_ambient(bad).is_err(), "{bad}");
        }
        assert_eq!(parse_exposure("2.5"), Ok(2.5));
        assert_eq!(parse_ev100("-3"), Ok(-3.0));
        assert_eq!(parse_ambient("0"), Ok(0.0));
        assert!(parse_exposure("NaN").unwrap_err().contains("exposure"));
    }

    #[test]
    fn names_round_trip_and_errors_list_the_choices() {
        for p in PipelineKind::ALL {
            assert_eq!(parse_pipeline(p.name()), Ok(p));
        }
        assert_eq!(parse_normal_codec("octa8"), Ok(NormalCodec::Octa8));
        let err = parse_gbuffer("tiny").expect_err("unknown");
        assert!(err.contains("full, packed, compact"), "{err}");
        assert_eq!(parse_size("1280x720"), Ok(UVec2::new(1280, 720)));
        assert!(parse_size("0x720").is_err() && parse_grid("1x2").is_err());
    }
}
