//! The one font pictures are drawn with: DejaVu Sans, shipped in `tracker-host/assets`
//! (plotters' pure-Rust `ab_glyph` renderer needs the font's bytes; no system font is looked
//! up), so pictures come out the same on every machine.

use std::sync::Once;

static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");
static REGISTER: Once = Once::new();

/// Registers the font as plotters' "sans-serif", once for the process; a failure shows up
/// as a drawing error where text is drawn.
pub fn register() {
    REGISTER.call_once(|| {
        let _ =
            plotters::style::register_font("sans-serif", plotters::style::FontStyle::Normal, FONT);
    });
}
