//! The embedded font (DejaVu Sans, see `fonts/LICENSE-DejaVu.txt`),
//! registered with plotters as the "sans-serif" family.

use std::sync::OnceLock;

use plotters::style::{FontDesc, FontFamily, FontStyle};

use crate::PlotError;

static DEJAVU_SANS: &[u8] = include_bytes!("../fonts/DejaVuSans.ttf");

/// Registers the embedded font once per process.
pub(crate) fn ensure() -> Result<(), PlotError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, DEJAVU_SANS).is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err(PlotError::Render {
            message: "the embedded font could not be loaded".into(),
        })
    }
}

/// The font at `px` pixels.
pub(crate) fn desc(px: f64) -> FontDesc<'static> {
    FontDesc::new(FontFamily::SansSerif, px, FontStyle::Normal)
}

/// Width and height in pixels of `text` at `px` pixels (0×0 for empty text).
pub(crate) fn text_size(text: &str, px: f64) -> (u32, u32) {
    if text.is_empty() {
        return (0, 0);
    }
    desc(px).box_size(text).unwrap_or_else(|_| {
        // Only reachable if the font failed to register; estimate.
        ((text.chars().count() as f64 * px * 0.6) as u32, px as u32)
    })
}
