//! The page of `batten plot-surface`: rows of equally sized panels (before, after), each row
//! with a title and, for colour maps, a colour bar with its numbers; written as PNG (the
//! `png` crate) or as SVG (each raster embedded as a PNG, the text as SVG text).
//!
//! PNG has no text, so the titles and numbers are drawn with the small bitmap font below
//! (3×5 cells, upper case, drawn at twice that size) and also stored in `tEXt` chunks.

use anyhow::{Context, anyhow};
use batten::surface::{BACKGROUND_RGB, Palette, Raster};

/// Height of a row's title strip, in pixels.
const TITLE_HEIGHT: usize = 24;
/// Space between panels and around the page.
const GAP: usize = 8;
/// Width of the colour bar itself.
const BAR_WIDTH: usize = 16;
/// Width reserved to the right of the rows for the bars and their numbers (when a row has
/// one).
const BAR_AREA: usize = 110;
/// Pixels per font cell.
const FONT_SCALE: usize = 2;
/// Horizontal advance of one character, in pixels.
const CHAR_ADVANCE: usize = 4 * FONT_SCALE;
/// Significant digits of the colour-bar numbers.
const BAR_DIGITS: usize = 3;

/// A colour bar: the palette from `lo` (bottom) to `hi` (top).
#[derive(Clone, Copy, Debug)]
pub struct Bar {
    pub lo: f64,
    pub hi: f64,
    pub palette: Palette,
}

/// One row: a title, its panels left to right, and an optional colour bar.
#[derive(Debug)]
pub struct Row {
    pub title: String,
    pub panels: Vec<Raster>,
    pub bar: Option<Bar>,
}

/// Rows of panels of one size.
#[derive(Debug)]
pub struct Figure {
    pub rows: Vec<Row>,
    pub panel: [usize; 2],
}

/// Where things go on the page.
struct Layout {
    width: usize,
    height: usize,
    columns: usize,
}

impl Figure {
    fn layout(&self) -> Layout {
        let columns = self.rows.iter().map(|r| r.panels.len()).max().unwrap_or(1);
        let [w, h] = self.panel;
        let bars = self.rows.iter().any(|r| r.bar.is_some());
        Layout {
            width: GAP + columns * (w + GAP) + if bars { BAR_AREA } else { 0 },
            height: GAP + self.rows.len() * (TITLE_HEIGHT + h + GAP),
            columns,
        }
    }

    /// Top-left corner of panel `c` of row `r`.
    fn panel_at(&self, r: usize, c: usize) -> (usize, usize) {
        let [w, h] = self.panel;
        (
            GAP + c * (w + GAP),
            GAP + r * (TITLE_HEIGHT + h + GAP) + TITLE_HEIGHT,
        )
    }

    /// Top-left corner of the colour bar of row `r`.
    fn bar_at(&self, r: usize, columns: usize) -> (usize, usize) {
        let (x, y) = self.panel_at(r, columns);
        (x + GAP, y + GAP)
    }

    fn bar_height(&self) -> usize {
        self.panel[1].saturating_sub(2 * GAP).max(1)
    }

    /// The numbers of a bar, top to bottom, with their offsets from the bar's top.
    fn bar_labels(&self, bar: &Bar) -> [(String, usize); 3] {
        let h = self.bar_height();
        [
            (crate::output::sig(bar.hi, BAR_DIGITS), 0),
            (
                crate::output::sig(0.5 * (bar.lo + bar.hi), BAR_DIGITS),
                h / 2,
            ),
            (crate::output::sig(bar.lo, BAR_DIGITS), h.saturating_sub(1)),
        ]
    }

    fn bar_raster(&self, bar: &Bar) -> Raster {
        let h = self.bar_height();
        let mut r = Raster::filled(BAR_WIDTH, h, BACKGROUND_RGB);
        for y in 0..h {
            let t = 1.0 - y as f64 / (h.max(2) - 1) as f64;
            for x in 0..BAR_WIDTH {
                r.put(x, y, bar.palette.colour(t));
            }
        }
        r
    }

    /// The page as one raster, text drawn in the bitmap font.
    pub fn raster(&self) -> Raster {
        let l = self.layout();
        let mut page = Raster::filled(l.width, l.height, BACKGROUND_RGB);
        for (r, row) in self.rows.iter().enumerate() {
            let (x, y) = self.panel_at(r, 0);
            draw_text(&mut page, &row.title, x, y - TITLE_HEIGHT + 6);
            for (c, p) in row.panels.iter().enumerate() {
                let (x, y) = self.panel_at(r, c);
                page.blit(p, x, y);
            }
            if let Some(bar) = &row.bar {
                let (bx, by) = self.bar_at(r, l.columns);
                page.blit(&self.bar_raster(bar), bx, by);
                for (text, dy) in self.bar_labels(bar) {
                    let ty = (by + dy).saturating_sub(5 * FONT_SCALE / 2);
                    draw_text(&mut page, &text, bx + BAR_WIDTH + 6, ty);
                }
            }
        }
        page
    }

    /// The page as PNG, with the titles in `tEXt` chunks.
    ///
    /// # Errors
    /// An encoder failure.
    pub fn png(&self) -> anyhow::Result<Vec<u8>> {
        let titles: Vec<&str> = self.rows.iter().map(|r| r.title.as_str()).collect();
        encode_png(&self.raster(), &[("Title", &titles.join("; "))])
    }

    /// The page as SVG: the panels and bars as embedded PNG images, the text as text.
    ///
    /// # Errors
    /// An encoder failure.
    pub fn svg(&self) -> anyhow::Result<String> {
        let l = self.layout();
        let [pw, ph] = self.panel;
        let mut s = format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" \
             viewBox=\"0 0 {w} {h}\" font-family=\"sans-serif\" font-size=\"13\">\n\
             <rect width=\"{w}\" height=\"{h}\" fill=\"white\"/>\n",
            w = l.width,
            h = l.height
        );
        let image = |s: &mut String, r: &Raster, x: usize, y: usize| -> anyhow::Result<()> {
            let data = base64(&encode_png(r, &[])?);
            s.push_str(&format!(
                "<image x=\"{x}\" y=\"{y}\" width=\"{}\" height=\"{}\" \
                 href=\"data:image/png;base64,{data}\"/>\n",
                r.width, r.height
            ));
            Ok(())
        };
        for (r, row) in self.rows.iter().enumerate() {
            let (x, y) = self.panel_at(r, 0);
            s.push_str(&format!(
                "<text x=\"{x}\" y=\"{}\">{}</text>\n",
                y - 7,
                xml_escape(&row.title)
            ));
            for (c, p) in row.panels.iter().enumerate() {
                let (x, y) = self.panel_at(r, c);
                image(&mut s, p, x, y)?;
                s.push_str(&format!(
                    "<rect x=\"{x}\" y=\"{y}\" width=\"{pw}\" height=\"{ph}\" fill=\"none\" \
                     stroke=\"#ccc\"/>\n"
                ));
            }
            if let Some(bar) = &row.bar {
                let (bx, by) = self.bar_at(r, l.columns);
                image(&mut s, &self.bar_raster(bar), bx, by)?;
                for (text, dy) in self.bar_labels(bar) {
                    s.push_str(&format!(
                        "<text x=\"{}\" y=\"{}\" dominant-baseline=\"middle\">{text}</text>\n",
                        bx + BAR_WIDTH + 6,
                        by + dy
                    ));
                }
            }
        }
        s.push_str("</svg>\n");
        Ok(s)
    }
}

/// PNG bytes of a raster (8-bit RGBA), with `tEXt` chunks.
fn encode_png(r: &Raster, text: &[(&str, &str)]) -> anyhow::Result<Vec<u8>> {
    let width = u32::try_from(r.width).map_err(|_| anyhow!("picture too wide"))?;
    let height = u32::try_from(r.height).map_err(|_| anyhow!("picture too tall"))?;
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, width, height);
        enc.set_color(png::ColorType::Rgba);
        enc.set_depth(png::BitDepth::Eight);
        for (k, v) in text {
            enc.add_text_chunk((*k).to_string(), (*v).to_string())
                .context("PNG text chunk")?;
        }
        let mut w = enc.write_header().context("PNG header")?;
        w.write_image_data(&r.rgba).context("PNG data")?;
        w.finish().context("PNG end")?;
    }
    Ok(out)
}

/// RFC 4648 base64 with padding (for the `data:` URIs of the SVG).
pub(crate) fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            chunk.get(1).copied().unwrap_or(0),
            chunk.get(2).copied().unwrap_or(0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                s.push(char::from(ALPHABET[((n >> (18 - 6 * k)) & 63) as usize]));
            } else {
                s.push('=');
            }
        }
    }
    s
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The 3×5 glyph of a character: five rows of three bits, the left column the highest bit.
/// Lower case is drawn as upper case; characters without a glyph leave a space.
fn glyph(c: char) -> [u8; 5] {
    match c.to_ascii_uppercase() {
        'A' => [2, 5, 7, 5, 5],
        'B' => [6, 5, 6, 5, 6],
        'C' => [3, 4, 4, 4, 3],
        'D' => [6, 5, 5, 5, 6],
        'E' => [7, 4, 6, 4, 7],
        'F' => [7, 4, 6, 4, 4],
        'G' => [3, 4, 5, 5, 3],
        'H' => [5, 5, 7, 5, 5],
        'I' => [7, 2, 2, 2, 7],
        'J' => [1, 1, 1, 5, 2],
        'K' => [5, 5, 6, 5, 5],
        'L' => [4, 4, 4, 4, 7],
        'M' => [5, 7, 7, 5, 5],
        'N' => [6, 5, 5, 5, 5],
        'O' => [2, 5, 5, 5, 2],
        'P' => [6, 5, 6, 4, 4],
        'Q' => [2, 5, 5, 6, 3],
        'R' => [6, 5, 6, 5, 5],
        'S' => [3, 4, 2, 1, 6],
        'T' => [7, 2, 2, 2, 2],
        'U' => [5, 5, 5, 5, 7],
        'V' => [5, 5, 5, 5, 2],
        'W' => [5, 5, 7, 7, 5],
        'X' => [5, 5, 2, 5, 5],
        'Y' => [5, 5, 2, 2, 2],
        'Z' => [7, 1, 2, 4, 7],
        '0' => [7, 5, 5, 5, 7],
        '1' => [2, 6, 2, 2, 7],
        '2' => [6, 1, 2, 4, 7],
        '3' => [6, 1, 2, 1, 6],
        '4' => [5, 5, 7, 1, 1],
        '5' => [7, 4, 6, 1, 6],
        '6' => [3, 4, 7, 5, 7],
        '7' => [7, 1, 2, 2, 2],
        '8' => [7, 5, 7, 5, 7],
        '9' => [7, 5, 7, 1, 6],
        '-' => [0, 0, 7, 0, 0],
        '+' => [0, 2, 7, 2, 0],
        '.' => [0, 0, 0, 0, 2],
        ',' => [0, 0, 0, 2, 4],
        ':' => [0, 2, 0, 2, 0],
        '=' => [0, 7, 0, 7, 0],
        '/' => [1, 1, 2, 4, 4],
        '(' => [1, 2, 2, 2, 1],
        ')' => [4, 2, 2, 2, 4],
        '_' => [0, 0, 0, 0, 7],
        _ => [0; 5],
    }
}

/// Draw `text` in black with its top-left corner at `(x, y)`.
fn draw_text(r: &mut Raster, text: &str, x: usize, y: usize) {
    for (k, c) in text.chars().enumerate() {
        let g = glyph(c);
        let x0 = x + k * CHAR_ADVANCE;
        for (row, bits) in g.iter().enumerate() {
            for col in 0..3 {
                if bits & (4 >> col) != 0 {
                    for dy in 0..FONT_SCALE {
                        for dx in 0..FONT_SCALE {
                            r.put(
                                x0 + col * FONT_SCALE + dx,
                                y + row * FONT_SCALE + dy,
                                [0, 0, 0],
                            );
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_rfc_4648() {
        let cases = [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ];
        for (plain, coded) in cases {
            assert_eq!(base64(plain.as_bytes()), coded, "{plain}");
        }
    }

    #[test]
    fn text_is_drawn_where_asked() {
        let mut r = Raster::filled(40, 20, BACKGROUND_RGB);
        draw_text(&mut r, "1", 2, 3);
        // "1" = [2, 6, 2, 2, 7]: the top row has only the middle cell, the bottom row all
        // three.
        assert_eq!(r.pixel(2 + FONT_SCALE, 3), [0, 0, 0]);
        assert_eq!(r.pixel(2, 3), BACKGROUND_RGB);
        for col in 0..3 {
            assert_eq!(r.pixel(2 + col * FONT_SCALE, 3 + 4 * FONT_SCALE), [0, 0, 0]);
        }
        // Unknown characters leave a space; drawing off the raster is clipped.
        draw_text(&mut r, "κ", 30, 15);
        draw_text(&mut r, "8", 38, 18);
    }

    #[test]
    fn the_page_has_room_for_every_panel_and_bar() {
        let panel = Raster::filled(50, 40, [10, 20, 30]);
        let fig = Figure {
            rows: vec![
                Row {
                    title: "a".into(),
                    panels: vec![panel.clone(), panel.clone()],
                    bar: Some(Bar {
                        lo: -1.0,
                        hi: 1.0,
                        palette: Palette::Diverging,
                    }),
                },
                Row {
                    title: "b".into(),
                    panels: vec![panel],
                    bar: None,
                },
            ],
            panel: [50, 40],
        };
        let page = fig.raster();
        assert_eq!(page.width, GAP + 2 * 58 + BAR_AREA);
        assert_eq!(page.height, GAP + 2 * (TITLE_HEIGHT + 48));
        let (x, y) = fig.panel_at(1, 0);
        assert_eq!(page.pixel(x + 25, y + 20), [10, 20, 30]);
        // The bar's top is the palette's high end.
        let (bx, by) = fig.bar_at(0, 2);
        assert_eq!(page.pixel(bx + 3, by), Palette::Diverging.colour(1.0));
        // Without bars, no room is kept for them.
        let no_bar = Figure {
            rows: vec![Row {
                title: "c".into(),
                panels: vec![Raster::filled(50, 40, [0, 0, 0])],
                bar: None,
            }],
            panel: [50, 40],
        };
        assert_eq!(no_bar.raster().width, GAP + 58);
        let svg = fig.svg().unwrap();
        assert_eq!(svg.matches("<image").count(), 4);
        assert!(svg.contains(">-1.00<") && svg.contains(">1.00<"), "{svg}");
    }
}
