//! Checks shared by the figure tests.

use std::path::Path;

/// Asserts `<stem>.png` is a PNG of `size` pixels and `<stem>.svg` contains every text in
/// `texts`; returns the SVG source.
pub(crate) fn check_figure(stem: &Path, size: (u32, u32), texts: &[&str]) -> String {
    let png = std::fs::read(stem.with_extension("png")).expect("png written");
    assert!(png.len() > 1000, "png too small: {} bytes", png.len());
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    assert_eq!(&png[12..16], b"IHDR");
    let w = u32::from_be_bytes(png[16..20].try_into().unwrap());
    let h = u32::from_be_bytes(png[20..24].try_into().unwrap());
    assert_eq!((w, h), size);
    let svg = std::fs::read_to_string(stem.with_extension("svg")).expect("svg written");
    assert!(svg.starts_with("<svg"), "not an svg");
    for t in texts {
        assert!(svg.contains(t), "svg lacks {t:?}");
    }
    svg
}
