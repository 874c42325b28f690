//! The embedded font (DejaVu Sans, see `assets/fonts/LICENSE-DejaVu.txt`), registered
//! with plotters' `ab_glyph` text renderer under the family name [`FAMILY`].

use plotters::style::{register_font, FontStyle};
use std::sync::Once;

/// Family name every text style in the report uses.
pub(crate) const FAMILY: &str = "sans-serif";

static DEJAVU_SANS: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");
static REGISTER: Once = Once::new();

/// Registers the embedded font once per process; later calls do nothing.
pub(crate) fn ensure_registered() {
    REGISTER.call_once(|| {
        // The bytes are a valid TrueType file checked in with the sources; failing to
        // parse them is a build defect, not a runtime condition.
        if register_font(FAMILY, FontStyle::Normal, DEJAVU_SANS).is_err() {
            panic!("embedded DejaVuSans.ttf is not a valid font");
        }
    });
}
