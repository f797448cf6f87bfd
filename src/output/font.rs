//! The one font every drawn text uses (chart labels, contact-sheet frame
//! numbers): DejaVu Sans Mono, embedded so no system font is needed.

use plotters::style::FontStyle;

/// The family name text styles ask for.
pub const FAMILY: &str = "sans-serif";

static FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSansMono.ttf");

/// Makes `FAMILY` drawable. Registering again is harmless.
pub fn register() -> Result<(), String> {
    plotters::style::register_font(FAMILY, FontStyle::Normal, FONT)
        .map_err(|_| "the embedded font is unreadable".to_string())
}
