//! What the CPU-only subcommands do: `depth-precision`, `culling-tests` and `codec-accuracy`
//! each print one markdown table computed without a GPU.

use crate::progress;
use anyhow::Result;

/// `depth-precision`: how accurately positions come back from reverse-Z and conventional depth,
/// over `samples` depths per decade.
pub(crate) fn depth_precision(samples: usize) -> Result<()> {
    print!("{}", crate::depth_precision::tables(samples.max(1)));
    Ok(())
}

/// `culling-tests`: the sphere–cluster tests' false-positive rates over `lights` random lights
/// placed from `seed`, after checking the count against the light limit.
pub(crate) fn culling_tests(lights: usize, seed: u64) -> Result<()> {
    manylight_core::light_count::check_app_lights(lights)
        .map_err(anyhow::Error::from)
        .map(|()| print!("{}", crate::culling_tests::table(lights, seed)))
}

/// `codec-accuracy`: the normal codecs' angular error over `samples` points of the sphere.
pub(crate) fn codec_accuracy(samples: usize) -> Result<()> {
    let samples = samples.max(1);
    let mut progress =
        progress::Progress::new(manylight_core::codec::NormalCodec::ALL.len() as u64 + 2, "codecs");
    let table = crate::codec_accuracy::table(samples, |label| progress.step(|| label.to_string()));
    progress.finish();
    print!("{table}");
    Ok(())
}
