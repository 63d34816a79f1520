//! The colour bar: a vertical strip of the colormap at the right edge, its maximum written above
//! and its minimum below in a 3×5 pixel font (digits, `.`, `-`, `+`, `e`), scaled with the image.

use super::{Colormap, Image};

const INK: [u8; 3] = [20, 20, 20];

/// Draws the bar for `map` on `lo..=hi` into `image`; does nothing if the image is too small
/// (under 48 × 48 pixels). The font pixel is 1/160 of the shorter side, so a tall, narrow
/// picture gets a bar as a square one of its width does. O(bar area + text).
pub(super) fn draw(image: &mut Image, map: Colormap, lo: f64, hi: f64) {
    let (w, h) = (image.width, image.height);
    if w < 48 || h < 48 {
        return;
    }
    let px = (w.min(h) / 160).max(1); // font pixel size
    let bar_w = (w / 40).max(4);
    // Exclusive right edge, inside a small margin; no bar if it would not fit (it always does
    // from 48 pixels wide, but no difference here is left unchecked).
    let Some(x1) = w.checked_sub(2 * px + 1) else { return };
    let Some(x0) = x1.checked_sub(bar_w) else { return };
    let (y0, y1) = (h / 5, h - h / 5);
    for y in y0..y1 {
        let t = (y1 - 1 - y) as f64 / (y1 - 1 - y0).max(1) as f64;
        let color = map.color(t);
        for x in x0..x1 {
            image.set_pixel(x, y, color);
        }
    }
    frame(image, x0.saturating_sub(1), y0.saturating_sub(1), x1, y1);
    text_right(image, &label(hi), x1, y0.saturating_sub(7 * px + 1), px);
    text_right(image, &label(lo), x1, y1 + 2 * px, px);
}

/// A short label: three significant digits, in scientific notation outside [0.01, 10⁴).
fn label(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || (0.01..10_000.0).contains(&a) {
        let decimals = if a == 0.0 { 0 } else { (2 - a.log10().floor() as i32).max(0) as usize };
        format!("{v:.decimals$}")
    } else {
        format!("{v:.2e}")
    }
}

fn frame(image: &mut Image, x0: u32, y0: u32, x1: u32, y1: u32) {
    for x in x0..=x1 {
        image.set_pixel(x, y0, INK);
        image.set_pixel(x, y1, INK);
    }
    for y in y0..=y1 {
        image.set_pixel(x0, y, INK);
        image.set_pixel(x1, y, INK);
    }
}

/// Writes `s` with its right edge at `x_end`, its top at `y`, each font pixel `px` wide.
fn text_right(image: &mut Image, s: &str, x_end: u32, y: u32, px: u32) {
    let advance = 4 * px;
    let width = advance * s.chars().count() as u32;
    let mut x = x_end.saturating_sub(width);
    for ch in s.chars() {
        if let Some(rows) = glyph(ch) {
            for (r, bits) in rows.iter().enumerate() {
                for c in 0..3u32 {
                    if bits >> (2 - c) & 1 == 1 {
                        block(image, x + c * px, y + r as u32 * px, px);
                    }
                }
            }
        }
        x += advance;
    }
}

fn block(image: &mut Image, x: u32, y: u32, px: u32) {
    for dy in 0..px {
        for dx in 0..px {
            image.set_pixel(x + dx, y + dy, INK);
        }
    }
}

/// Five rows of three bits (left pixel = bit 2).
fn glyph(ch: char) -> Option<[u8; 5]> {
    Some(match ch {
        '0' => [0b111, 0b101, 0b101, 0b101, 0b111],
        '1' => [0b010, 0b110, 0b010, 0b010, 0b111],
        '2' => [0b111, 0b001, 0b111, 0b100, 0b111],
        '3' => [0b111, 0b001, 0b111, 0b001, 0b111],
        '4' => [0b101, 0b101, 0b111, 0b001, 0b001],
        '5' => [0b111, 0b100, 0b111, 0b001, 0b111],
        '6' => [0b111, 0b100, 0b111, 0b101, 0b111],
        '7' => [0b111, 0b001, 0b001, 0b001, 0b001],
        '8' => [0b111, 0b101, 0b111, 0b101, 0b111],
        '9' => [0b111, 0b101, 0b111, 0b001, 0b111],
        '.' => [0b000, 0b000, 0b000, 0b000, 0b010],
        '-' => [0b000, 0b000, 0b111, 0b000, 0b000],
        '+' => [0b000, 0b010, 0b111, 0b010, 0b000],
        'e' => [0b000, 0b111, 0b101, 0b110, 0b011],
        _ => return None,
    })
}
