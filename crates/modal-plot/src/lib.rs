//! `modal-plot`: what every PNG plot of modal shares.
//!
//! - **Text in a real font.** DejaVu Sans (`assets/fonts/DejaVuSans.ttf`,
//!   Bitstream Vera licence, see `assets/fonts/LICENSE-DejaVu.txt`) is
//!   compiled into the binary and rasterized with `ab_glyph` (the font engine
//!   of plotters' `ab_glyph` feature), so plots need no system font library
//!   and look the same on every machine. [`draw_text`] lays a string out
//!   itself — advance widths, kerning, each glyph at its own bounding box —
//!   and blends the glyph coverage into any plotters drawing area, horizontal
//!   or rotated to read upwards. (plotters 0.3.7's own `ab_glyph` text drops
//!   each glyph's left bearing, which visibly breaks words such as
//!   "TET10" apart; hence our own layout.)
//! - [`nice_ticks`]: tick values at 1, 2 or 5 × 10ᵏ steps.
//! - [`heat`]: the colour map of spectrograms, dark blue → magenta → yellow,
//!   lightness increasing, and [`draw_colorbar`] which labels it.
//!
//! Input: strings, sizes, values, a drawing area. Output: pixels; nothing is
//! printed.

use std::sync::OnceLock;

use ab_glyph::{Font, FontRef, PxScale, ScaleFont};
use plotters::coord::Shift;
use plotters::prelude::*;
pub use plotters::style::text_anchor::{HPos, VPos};

/// DejaVu Sans 2.37.
static DEJAVU_SANS: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");

fn face() -> &'static FontRef<'static> {
    static FACE: OnceLock<FontRef<'static>> = OnceLock::new();
    // The embedded file is a valid TrueType font (tested): parsing cannot fail.
    FACE.get_or_init(|| FontRef::try_from_slice(DEJAVU_SANS).expect("embedded DejaVu Sans parses"))
}

/// How a string is drawn: size in pixels (em height), anchor, direction, colour.
#[derive(Clone, Copy)]
pub struct Text {
    /// Font size [px].
    pub size: f32,
    /// Which point of the text box lies on the given position, horizontally …
    pub h: HPos,
    /// … and vertically (`Top`/`Bottom` are the ascender and descender lines).
    pub v: VPos,
    /// Rotated 90° counter-clockwise, reading bottom to top.
    pub up: bool,
    /// Colour.
    pub color: RGBColor,
}

impl Text {
    /// Black text of `size` px anchored at its top-left corner.
    pub fn new(size: f32) -> Text {
        Text { size, h: HPos::Left, v: VPos::Top, up: false, color: BLACK }
    }

    /// The same text anchored at `(h, v)`.
    pub fn at(self, h: HPos, v: VPos) -> Text {
        Text { h, v, ..self }
    }

    /// The same text reading upwards.
    pub fn upwards(self) -> Text {
        Text { up: true, ..self }
    }
}

/// Width [px] of `text` at `size` px: advances plus kerning.
pub fn text_width(text: &str, size: f32) -> f32 {
    let font = face().as_scaled(PxScale::from(size));
    let mut width = 0.0;
    let mut prev = None;
    for c in text.chars() {
        let id = font.glyph_id(c);
        if let Some(p) = prev {
            width += font.kern(p, id);
        }
        width += font.h_advance(id);
        prev = Some(id);
    }
    width
}

/// Draws `text` at `pos` (pixels of `area`) in the embedded font.
pub fn draw_text<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    pos: (i32, i32),
    style: &Text,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let scale = PxScale::from(style.size);
    let font = face().as_scaled(scale);
    let dx = match style.h {
        HPos::Left => 0.0,
        HPos::Center => -0.5 * text_width(text, style.size),
        HPos::Right => -text_width(text, style.size),
    };
    let dy = match style.v {
        VPos::Top => font.ascent(),
        VPos::Center => 0.5 * (font.ascent() + font.descent()),
        VPos::Bottom => font.descent(),
    };
    // Glyph coverage in text coordinates (x along the text, y down from the baseline).
    let mut coverage = Vec::new();
    let mut caret = 0.0;
    let mut prev = None;
    for c in text.chars() {
        let id = font.glyph_id(c);
        if let Some(p) = prev {
            caret += font.kern(p, id);
        }
        prev = Some(id);
        let glyph = id.with_scale_and_position(scale, ab_glyph::point(caret + dx, dy));
        if let Some(outline) = face().outline_glyph(glyph) {
            let b = outline.px_bounds();
            outline.draw(|x, y, c| coverage.push((b.min.x as i32 + x as i32, b.min.y as i32 + y as i32, c)));
        }
        caret += font.h_advance(id);
    }
    for (x, y, c) in coverage {
        if c <= 0.0 {
            continue;
        }
        let p = if style.up { (pos.0 + y, pos.1 - x) } else { (pos.0 + x, pos.1 + y) };
        area.draw_pixel(p, &style.color.mix(f64::from(c.min(1.0))))?;
    }
    Ok(())
}

/// Tick values in `lo..=hi` at a step of 1, 2 or 5 × 10ᵏ, at most `max_ticks`
/// of them (at least 2 when `hi > lo`); values are rounded to the step's
/// decimals so they print cleanly.
pub fn nice_ticks(lo: f64, hi: f64, max_ticks: usize) -> Vec<f64> {
    if hi <= lo || lo.is_nan() || hi.is_nan() || !lo.is_finite() || !hi.is_finite() {
        return vec![lo];
    }
    let raw = (hi - lo) / max_ticks.max(2) as f64;
    let magnitude = 10f64.powf(raw.log10().floor());
    let step =
        [1.0, 2.0, 5.0, 10.0].iter().map(|m| m * magnitude).find(|&s| s >= raw).unwrap_or(10.0 * magnitude);
    let decimals = (-step.log10().floor()).max(0.0) as i32;
    let round = |v: f64| {
        let k = 10f64.powi(decimals);
        (v * k).round() / k
    };
    let first = (lo / step).ceil() as i64;
    let last = (hi / step + 1e-9).floor() as i64;
    (first..=last).map(|k| round(k as f64 * step)).collect()
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
    if y1 <= y0 + 2 || hi <= lo {
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
        // A real minus sign (U+2212), as typeset numbers have.
        let text = format!("{v}").replace('-', "\u{2212}");
        draw_text(area, &text, (x1 + 8, y), &Text::new(14.0).at(HPos::Left, VPos::Center))?;
    }
    draw_text(area, label, (w - 22, (y0 + y1) / 2), &Text::new(16.0).at(HPos::Center, VPos::Top).upwards())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Columns that hold at least one dark pixel, in a `w`×`h` RGB buffer.
    fn inked_columns(pixels: &[u8], w: usize) -> Vec<bool> {
        let mut cols = vec![false; w];
        for (i, p) in pixels.chunks(3).enumerate() {
            if p[0] < 128 {
                cols[i % w] = true;
            }
        }
        cols
    }

    #[test]
    fn text_is_drawn_where_its_width_says() {
        let (w, h) = (300usize, 60usize);
        let mut pixels = vec![255u8; w * h * 3];
        let width = text_width("TET10 Hz", 30.0);
        assert!(width > 90.0 && width < 160.0, "{width}");
        {
            let area = BitMapBackend::with_buffer(&mut pixels, (w as u32, h as u32)).into_drawing_area();
            draw_text(&area, "TET10 Hz", (150, 30), &Text::new(30.0).at(HPos::Center, VPos::Center)).unwrap();
            area.present().unwrap();
        }
        let cols = inked_columns(&pixels, w);
        let first = cols.iter().position(|&c| c).unwrap() as f32;
        let last = cols.iter().rposition(|&c| c).unwrap() as f32;
        // Centred, and the ink spans the advance width up to the side bearings.
        assert!((0.5 * (first + last) - 150.0).abs() < 4.0, "{first}..{last}");
        assert!((last - first) > width - 8.0 && (last - first) <= width, "{first}..{last} vs {width}");
        // No gap between letters wider than the space's advance: "TET10" is one word.
        let gaps: Vec<usize> =
            cols[first as usize..last as usize].split(|&c| c).map(<[bool]>::len).filter(|&n| n > 0).collect();
        assert_eq!(gaps.iter().filter(|&&g| g >= 6).count(), 1, "one word gap: {gaps:?}");
    }

    #[test]
    fn upward_text_is_rotated() {
        let (w, h) = (60usize, 200usize);
        let mut pixels = vec![255u8; w * h * 3];
        {
            let area = BitMapBackend::with_buffer(&mut pixels, (w as u32, h as u32)).into_drawing_area();
            draw_text(
                &area,
                "frequency",
                (30, 100),
                &Text::new(20.0).at(HPos::Center, VPos::Center).upwards(),
            )
            .unwrap();
            area.present().unwrap();
        }
        let cols = inked_columns(&pixels, w);
        let span = cols.iter().filter(|&&c| c).count();
        assert!(span < 25, "the text is narrow horizontally ({span} columns)");
        let rows = pixels.chunks(w * 3).filter(|row| row.chunks(3).any(|p| p[0] < 128)).count();
        assert!(rows > 60, "and tall ({rows} rows)");
    }

    #[test]
    fn ticks_are_round_and_inside() {
        assert_eq!(nice_ticks(0.0, 4.0, 8), vec![0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0]);
        assert_eq!(nice_ticks(0.0, 24.0, 6), vec![0.0, 5.0, 10.0, 15.0, 20.0]);
        assert_eq!(nice_ticks(0.0, 0.3, 3), vec![0.0, 0.1, 0.2, 0.3]);
        assert_eq!(nice_ticks(1.0, 1.0, 5), vec![1.0]);
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
