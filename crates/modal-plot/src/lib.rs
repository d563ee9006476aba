//! `modal-plot`: what every PNG plot of modal shares.
//!
//! - A real font: DejaVu Sans (`assets/fonts/DejaVuSans.ttf`, Bitstream Vera
//!   licence, see `assets/fonts/LICENSE-DejaVu.txt`) is compiled into the
//!   binary and registered with plotters' `ab_glyph` text renderer under
//!   [`FAMILY`], so plots need no system font library and look the same on
//!   every machine. [`font`] registers it on first use.
//! - [`heat`]: the colour map of spectrograms, dark blue → magenta → yellow,
//!   monotonic in lightness, and [`draw_colorbar`] which labels it.
//!
//! Input: sizes, values in [0, 1], a drawing area. Output: styles and pixels;
//! nothing is printed.

use std::sync::Once;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::FontTransform;

/// Font family name the embedded font is registered under.
pub const FAMILY: &str = "sans-serif";

/// DejaVu Sans 2.37.
static DEJAVU_SANS: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");

/// Registers the embedded font (once per process).
pub fn register() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The embedded file is a valid TrueType font (tested), so this cannot fail.
        let _ = plotters::style::register_font(FAMILY, FontStyle::Normal, DEJAVU_SANS);
    });
}

/// Black text of `size` pixels in the embedded font.
pub fn font(size: u32) -> TextStyle<'static> {
    register();
    (FAMILY, size as f64).into_font().color(&BLACK)
}

/// [`font`] rotated to read bottom-to-top (vertical axis labels).
pub fn font_up(size: u32) -> TextStyle<'static> {
    font(size).transform(FontTransform::Rotate270)
}

/// [`font`] anchored at `(h, v)` of the text box.
pub fn font_at(size: u32, h: HPos, v: VPos) -> TextStyle<'static> {
    font(size).pos(Pos::new(h, v))
}

/// Colour of `x` in [0, 1] (clamped): dark blue → magenta → yellow.
pub fn heat(x: f64) -> RGBColor {
    let x = x.clamp(0.0, 1.0);
    let r = (255.0 * (1.5 * x).min(1.0)) as u8;
    let g = (255.0 * (2.0 * x - 1.0).clamp(0.0, 1.0)) as u8;
    let b = (255.0 * (0.35 + 0.65 * (1.0 - (2.0 * x - 0.6).abs()).clamp(0.0, 1.0)) * (1.0 - x * x)) as u8;
    RGBColor(r, g, b)
}

/// Draws a vertical colour bar of [`heat`] for values `lo..hi` in `area`,
/// spanning the rows `y0..=y1` of the area (e.g. those of the plot it
/// explains): the ramp (low at the bottom) in a frame, ticks every `step`
/// with labels on the right, and `label` along the right edge.
pub fn draw_colorbar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (lo, hi): (f64, f64),
    step: f64,
    (y0, y1): (i32, i32),
    label: &str,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let (w, _) = area.dim_in_pixel();
    let w = w as i32;
    let (x0, x1) = (6, 6 + (w / 5).clamp(12, 24));
    if y1 <= y0 + 2 {
        return Ok(());
    }
    for y in y0..=y1 {
        let level = (y1 - y) as f64 / (y1 - y0) as f64;
        area.draw(&PathElement::new(vec![(x0, y), (x1, y)], heat(level)))?;
    }
    area.draw(&Rectangle::new([(x0, y0), (x1, y1)], BLACK.stroke_width(1)))?;
    let ticks = ((hi - lo) / step).floor() as i32;
    for k in 0..=ticks {
        let v = lo + k as f64 * step;
        let y = y1 - ((v - lo) / (hi - lo) * (y1 - y0) as f64).round() as i32;
        area.draw(&PathElement::new(vec![(x1, y), (x1 + 5, y)], BLACK))?;
        area.draw_text(&format!("{v}"), &font_at(14, HPos::Left, VPos::Center), (x1 + 8, y))?;
    }
    area.draw_text(label, &font_up(16).pos(Pos::new(HPos::Center, VPos::Bottom)), (w - 4, (y0 + y1) / 2))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_embedded_font_draws_text() {
        let mut pixels = vec![255u8; 200 * 60 * 3];
        {
            let area = BitMapBackend::with_buffer(&mut pixels, (200, 60)).into_drawing_area();
            area.draw_text("Hz 0.5", &font(30), (5, 10)).expect("text drawn");
            let (w, h) = area.estimate_text_size("Hz 0.5", &font(30)).expect("text measured");
            assert!(w > 60 && w < 150 && h > 15 && h < 45, "{w}x{h}");
            area.present().unwrap();
        }
        let dark = pixels.chunks(3).filter(|p| p[0] < 128).count();
        assert!(dark > 150, "glyphs were drawn ({dark} dark pixels)");
    }

    #[test]
    fn heat_runs_dark_to_bright() {
        let luma = |c: RGBColor| 0.2126 * c.0 as f64 + 0.7152 * c.1 as f64 + 0.0722 * c.2 as f64;
        assert!(luma(heat(0.0)) < 60.0);
        assert_eq!(heat(1.0), RGBColor(255, 255, 0));
        assert_eq!(heat(-3.0), heat(0.0));
        let mut last = -1.0;
        for k in 0..=20 {
            let l = luma(heat(k as f64 / 20.0));
            assert!(l >= last - 1.0, "lightness falls at {k}");
            last = l;
        }
    }
}
