//! Environment decoding against small hostile files built in memory: what loads, what is
//! refused with which error, and what is clamped and counted.

use image::{DynamicImage, ImageFormat, Rgb32FImage, RgbImage};
use manylight_scene::environment::{
    DecodedEnvironment, EnvironmentBudget, EnvironmentError, MAX_RADIANCE, decode_environment,
    load_environment, sanitize_radiance,
};
use proptest::prelude::*;
use std::io::Cursor;

/// A Radiance header for a `width` x `height` image, top row first.
fn hdr_header(width: u32, height: u32) -> Vec<u8> {
    format!("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {height} +X {width}\n").into_bytes()
}

/// A Radiance file with flat (not run-length encoded) RGBE texels; value = c * 2^(e - 136).
fn hdr_file(width: u32, height: u32, texel: impl Fn(u32, u32) -> [u8; 4]) -> Vec<u8> {
    let mut bytes = hdr_header(width, height);
    for y in 0..height {
        for x in 0..width {
            bytes.extend_from_slice(&texel(x, y));
        }
    }
    bytes
}

/// An OpenEXR file of `f32` RGB texels, written by the `image` crate.
fn exr_file(width: u32, height: u32, texel: impl Fn(u32, u32) -> [f32; 3]) -> Vec<u8> {
    let image = Rgb32FImage::from_fn(width, height, |x, y| image::Rgb(texel(x, y)));
    let mut bytes = Cursor::new(Vec::new());
    DynamicImage::ImageRgb32F(image).write_to(&mut bytes, ImageFormat::OpenExr).expect("encode EXR");
    bytes.into_inner()
}

fn decode(bytes: &[u8], name: &str) -> Result<DecodedEnvironment, EnvironmentError> {
    decode_environment(bytes, name, &EnvironmentBudget::default())
}

/// The error of a refused file, checking that its message names the file.
fn refused(bytes: &[u8], name: &str) -> EnvironmentError {
    let error = decode(bytes, name).expect_err("the file should be refused");
    assert!(error.to_string().contains(name), "the message does not name `{name}`: {error}");
    error
}

#[test]
fn a_tiny_radiance_panorama_decodes_to_its_values() {
    // Texel (x, y) holds (x + 1, y + 1, 2) exactly (exponent 136 scales by 1); one texel holds
    // (1, 0.5, 0.25) with exponent 129 (scale 2^-7).
    let bytes = hdr_file(8, 4, |x, y| {
        if (x, y) == (5, 2) { [128, 64, 32, 129] } else { [x as u8 + 1, y as u8 + 1, 2, 136] }
    });
    let decoded = decode(&bytes, "tiny.hdr").expect("decodes");
    assert_eq!((decoded.image.width, decoded.image.height), (8, 4));
    assert_eq!(decoded.clamped_texels, 0);
    assert_eq!(decoded.image.texels[0], [1.0, 1.0, 2.0]);
    assert_eq!(decoded.image.texels[3 * 8 + 7], [8.0, 4.0, 2.0]);
    assert_eq!(decoded.image.texels[2 * 8 + 5], [1.0, 0.5, 0.25]);
}

#[test]
fn an_openexr_panorama_decodes_to_its_values() {
    let texel = |x: u32, y: u32| [x as f32 * 0.25, y as f32 * 1.5, 1000.0];
    let decoded = decode(&exr_file(16, 8, texel), "tiny.exr").expect("decodes");
    assert_eq!((decoded.image.width, decoded.image.height), (16, 8));
    assert_eq!(decoded.clamped_texels, 0);
    for (i, t) in decoded.image.texels.iter().enumerate() {
        assert_eq!(*t, texel(i as u32 % 16, i as u32 / 16));
    }
}

#[test]
fn nan_infinite_negative_and_too_bright_texels_are_clamped_and_counted() {
    let texel = |x: u32, y: u32| match (x, y) {
        (0, 0) => [f32::NAN, 1.0, 1.0],
        (1, 0) => [f32::INFINITY, 1.0, 1.0],
        (2, 0) => [f32::NEG_INFINITY, -1.0, 1.0],
        (3, 0) => [1.0e6, 1.0, 1.0],
        (4, 0) => [f32::NAN, f32::NAN, f32::INFINITY],
        _ => [0.5, 0.5, 0.5],
    };
    let decoded = decode(&exr_file(8, 4, texel), "hostile.exr").expect("decodes");
    assert_eq!(decoded.clamped_texels, 5);
    let t = &decoded.image.texels;
    assert_eq!(t[0], [0.0, 1.0, 1.0]);
    assert_eq!(t[1], [MAX_RADIANCE, 1.0, 1.0]);
    assert_eq!(t[2], [0.0, 0.0, 1.0]);
    assert_eq!(t[3], [MAX_RADIANCE, 1.0, 1.0]);
    assert_eq!(t[4], [0.0, 0.0, MAX_RADIANCE]);
    assert!(t.iter().flatten().all(|c| c.is_finite() && (0.0..=MAX_RADIANCE).contains(c)));
}

#[test]
fn a_radiance_texel_brighter_than_f16_is_clamped_and_counted() {
    // Exponent 255 scales by 2^119.
    let bytes = hdr_file(8, 4, |x, y| if (x, y) == (3, 1) { [200, 10, 0, 255] } else { [1, 1, 2, 136] });
    let decoded = decode(&bytes, "sun.hdr").expect("decodes");
    assert_eq!(decoded.clamped_texels, 1);
    assert_eq!(decoded.image.texels[8 + 3], [MAX_RADIANCE, MAX_RADIANCE, 0.0]);
}

#[test]
fn sanitize_radiance_repairs_only_what_the_gpu_cannot_store() {
    assert_eq!(sanitize_radiance([0.0, 1.0, MAX_RADIANCE]), ([0.0, 1.0, MAX_RADIANCE], false));
    assert_eq!(sanitize_radiance([f32::MIN_POSITIVE / 2.0; 3]), ([f32::MIN_POSITIVE / 2.0; 3], false));
    let (texel, clamped) = sanitize_radiance([-0.0, 2.0, 3.0]);
    assert!(!clamped && texel[0].to_bits() == 0, "-0 becomes +0 without counting: {texel:?}");
    assert_eq!(sanitize_radiance([f32::NAN, 2.0, 3.0]), ([0.0, 2.0, 3.0], true));
    assert_eq!(sanitize_radiance([1.0, -1e-30, 3.0]), ([1.0, 0.0, 3.0], true));
    assert_eq!(sanitize_radiance([1.0, 2.0, 65505.0]), ([1.0, 2.0, MAX_RADIANCE], true));
    assert_eq!(sanitize_radiance([f32::INFINITY, f32::NEG_INFINITY, 0.0]), ([MAX_RADIANCE, 0.0, 0.0], true));
}

#[test]
fn truncated_files_are_refused() {
    let hdr = hdr_file(8, 4, |_, _| [1, 1, 2, 136]);
    let header_len = hdr_header(8, 4).len();
    // Within the header only a cut at a line's end reads as truncation ("EOF in header"); the
    // decoder parses a cut line as a whole one and calls it corrupt.
    let signature_line = "#?RADIANCE\n".len();
    for cut in [hdr.len() - 1, header_len + 10, header_len, signature_line] {
        let e = refused(&hdr[..cut], "cut.hdr");
        assert!(matches!(e, EnvironmentError::Truncated { .. }), "HDR cut at {cut}: {e}");
    }
    let exr = exr_file(8, 4, |_, _| [1.0; 3]);
    for cut in [exr.len() - 1, exr.len() / 2, 40] {
        let e = refused(&exr[..cut], "cut.exr");
        assert!(matches!(e, EnvironmentError::Truncated { .. }), "EXR cut at {cut}: {e}");
    }
}

#[test]
fn a_header_claiming_65536_texels_across_is_refused_before_decoding() {
    let e = refused(&hdr_header(65536, 32768), "huge.hdr");
    assert!(
        matches!(
            e,
            EnvironmentError::TooLarge { width: 65536, height: 32768, max_width: 8192, max_height: 4096, .. }
        ),
        "{e}"
    );
    // The largest size a header can state, which overflows any byte count.
    let e = refused(&hdr_header(u32::MAX, u32::MAX), "overflow.hdr");
    assert!(matches!(e, EnvironmentError::TooLarge { .. } | EnvironmentError::Corrupt { .. }), "{e}");
}

#[test]
fn an_openexr_header_claiming_65536_texels_across_is_refused() {
    let mut exr = exr_file(8, 4, |_, _| [1.0; 3]);
    // The value of attribute `name` of type `kind` (after its 4-byte size).
    let value_at = |exr: &[u8], name: &[u8], kind: &[u8]| {
        let key = [name, b"\0", kind, b"\0"].concat();
        exr.windows(key.len()).position(|w| w == key).expect("attribute") + key.len() + 4
    };
    // Widen the display and data windows to 65536 x 32768 (box2i: xmin, ymin, xmax, ymax).
    for name in [&b"displayWindow"[..], b"dataWindow"] {
        let at = value_at(&exr, name, b"box2i");
        exr[at + 8..at + 12].copy_from_slice(&65535i32.to_le_bytes());
        exr[at + 12..at + 16].copy_from_slice(&32767i32.to_le_bytes());
    }
    // The image crate writes 64 x 64 tiles: 1024 x 512 of them.
    let at = value_at(&exr, b"chunkCount", b"int");
    exr[at..at + 4].copy_from_slice(&(1024i32 * 512).to_le_bytes());
    let e = refused(&exr, "huge.exr");
    assert!(matches!(e, EnvironmentError::TooLarge { width: 65536, height: 32768, .. }), "{e}");
}

#[test]
fn a_one_texel_image_is_refused_naming_its_size() {
    let e = refused(&hdr_file(1, 1, |_, _| [1, 1, 2, 136]), "dot.hdr");
    assert!(matches!(e, EnvironmentError::TooSmall { width: 1, height: 1, .. }), "{e}");
    assert!(e.to_string().contains("1x1"), "{e}");
    let e = refused(&hdr_header(0, 0), "empty-size.hdr");
    assert!(matches!(e, EnvironmentError::TooSmall { .. } | EnvironmentError::Corrupt { .. }), "{e}");
}

#[test]
fn a_panorama_three_times_as_wide_as_high_is_refused() {
    let e = refused(&hdr_file(24, 8, |_, _| [1, 1, 2, 136]), "wide.hdr");
    assert!(matches!(e, EnvironmentError::NotEquirectangular { width: 24, height: 8, .. }), "{e}");
    assert!(e.to_string().contains("24x8"), "{e}");
    // A texel off twice the height is still a panorama.
    assert!(decode(&hdr_file(201, 100, |_, _| [1, 1, 2, 136]), "nearly.hdr").is_ok());
}

#[test]
fn images_without_high_dynamic_range_are_refused() {
    let mut png = Cursor::new(Vec::new());
    DynamicImage::ImageRgb8(RgbImage::new(16, 8)).write_to(&mut png, ImageFormat::Png).expect("encode PNG");
    let e = refused(png.get_ref(), "photo.hdr");
    assert!(matches!(e, EnvironmentError::NotHdr { .. }) && e.to_string().contains("Png"), "{e}");
    let mut jpeg = Cursor::new(Vec::new());
    DynamicImage::ImageRgb8(RgbImage::new(16, 8))
        .write_to(&mut jpeg, ImageFormat::Jpeg)
        .expect("encode JPEG");
    assert!(matches!(refused(jpeg.get_ref(), "photo.jpg"), EnvironmentError::NotHdr { .. }));
    assert!(matches!(refused(b"not an image at all", "garbage.hdr"), EnvironmentError::NotHdr { .. }));
    assert!(matches!(refused(b"", "empty.exr"), EnvironmentError::NotHdr { .. }));
}

#[test]
fn the_budget_bounds_size_and_bytes() {
    let bytes = hdr_file(32, 16, |_, _| [1, 1, 2, 136]);
    let narrow = EnvironmentBudget { max_width: 16, ..EnvironmentBudget::default() };
    let e = decode_environment(&bytes, "budget.hdr", &narrow).expect_err("over the width");
    assert!(matches!(e, EnvironmentError::TooLarge { width: 32, max_width: 16, .. }), "{e}");
    // 32 x 16 RGB f32 texels take 6,144 bytes.
    let small = EnvironmentBudget { max_bytes: 6143, ..EnvironmentBudget::default() };
    let e = decode_environment(&bytes, "budget.hdr", &small).expect_err("over the bytes");
    assert!(matches!(e, EnvironmentError::OverMemoryBudget { needed: 6144, max_bytes: 6143, .. }), "{e}");
    assert!(e.to_string().contains("budget.hdr"), "{e}");
    let exact = EnvironmentBudget { max_bytes: 6144, ..EnvironmentBudget::default() };
    assert!(decode_environment(&bytes, "budget.hdr", &exact).is_ok());
}

#[test]
fn load_environment_reads_a_file_and_names_a_missing_one() {
    let dir = std::env::temp_dir().join(format!("manylight_environment_test_{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary directory");
    let path = dir.join("tiny.hdr");
    std::fs::write(&path, hdr_file(8, 4, |_, _| [1, 1, 2, 136])).expect("write");
    let loaded = load_environment(&path, &EnvironmentBudget::default());
    let missing = dir.join("missing.hdr");
    let e = load_environment(&missing, &EnvironmentBudget::default()).expect_err("missing");
    std::fs::remove_dir_all(&dir).expect("clean up");
    assert_eq!(loaded.expect("loads").image.texels[0], [1.0, 1.0, 2.0]);
    assert!(matches!(e, EnvironmentError::Io { .. }) && e.to_string().contains("missing.hdr"), "{e}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Corrupting any bytes of a valid file gives an environment or an error, never a panic,
    /// and whatever decodes is finite, non-negative and at most MAX_RADIANCE.
    #[test]
    fn corrupted_files_never_panic(
        exr in any::<bool>(),
        edits in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8),
        cut in any::<prop::sample::Index>(),
    ) {
        let mut bytes = if exr {
            exr_file(16, 8, |x, y| [x as f32, y as f32, 0.5])
        } else {
            hdr_file(16, 8, |x, y| [x as u8 + 3, y as u8 + 3, 7, 130])
        };
        for (at, value) in edits {
            let i = at.index(bytes.len());
            bytes[i] = value;
        }
        let keep = bytes.len() - cut.index(bytes.len() / 4);
        let budget = EnvironmentBudget { max_width: 1024, max_height: 512, max_bytes: 1 << 24 };
        if let Ok(decoded) = decode_environment(&bytes[..keep], "fuzz", &budget) {
            prop_assert!(decoded.image.texels.iter().flatten().all(|c| (0.0..=MAX_RADIANCE).contains(c)));
        }
    }
}
