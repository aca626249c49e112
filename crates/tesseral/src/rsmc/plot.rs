//! A small line plot (area against steps) drawn into a PNG, with a built-in 3×5
//! pixel font for the tick labels, so no system fonts are needed.
//!
//! ```
//! let png = tesseral::rsmc::plot::line_plot_png(&[(0.0, 6.0), (100.0, 40.0)], 320, 200).unwrap();
//! assert_eq!(&png[1..4], b"PNG");
//! ```

/// Errors of the plot encoder.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PlotError {
    /// The image size is out of range (each side 64 to 8192 pixels).
    #[error("image size {0}x{1} out of range")]
    Size(u32, u32),
    /// The PNG encoder failed.
    #[error("png: {0}")]
    Png(#[from] png::EncodingError),
}

const GLYPHS: &[(char, [u8; 5])] = &[
    ('0', [0b111, 0b101, 0b101, 0b101, 0b111]),
    ('1', [0b010, 0b110, 0b010, 0b010, 0b111]),
    ('2', [0b111, 0b001, 0b111, 0b100, 0b111]),
    ('3', [0b111, 0b001, 0b111, 0b001, 0b111]),
    ('4', [0b101, 0b101, 0b111, 0b001, 0b001]),
    ('5', [0b111, 0b100, 0b111, 0b001, 0b111]),
    ('6', [0b111, 0b100, 0b111, 0b101, 0b111]),
    ('7', [0b111, 0b001, 0b010, 0b010, 0b010]),
    ('8', [0b111, 0b101, 0b111, 0b101, 0b111]),
    ('9', [0b111, 0b101, 0b111, 0b001, 0b111]),
    ('.', [0b000, 0b000, 0b000, 0b000, 0b010]),
    ('k', [0b100, 0b101, 0b110, 0b101, 0b101]),
    ('M', [0b101, 0b111, 0b111, 0b101, 0b101]),
    ('G', [0b111, 0b100, 0b101, 0b101, 0b111]),
    ('s', [0b011, 0b100, 0b010, 0b001, 0b110]),
    ('t', [0b010, 0b111, 0b010, 0b010, 0b011]),
    ('e', [0b111, 0b101, 0b111, 0b100, 0b111]),
    ('p', [0b111, 0b101, 0b111, 0b100, 0b100]),
    ('a', [0b011, 0b101, 0b111, 0b101, 0b101]),
    ('r', [0b110, 0b101, 0b110, 0b101, 0b101]),
    (' ', [0; 5]),
];

struct Canvas {
    w: u32,
    h: u32,
    px: Vec<u8>,
}

impl Canvas {
    fn set(&mut self, x: i64, y: i64, c: [u8; 3]) {
        if x >= 0 && y >= 0 && (x as u32) < self.w && (y as u32) < self.h {
            let i = 3 * (y as usize * self.w as usize + x as usize);
            self.px[i..i + 3].copy_from_slice(&c);
        }
    }
    fn line(&mut self, x0: i64, y0: i64, x1: i64, y1: i64, c: [u8; 3]) {
        let (dx, dy) = ((x1 - x0).abs(), -(y1 - y0).abs());
        let (sx, sy) = (if x0 < x1 { 1 } else { -1 }, if y0 < y1 { 1 } else { -1 });
        let (mut x, mut y, mut err) = (x0, y0, dx + dy);
        loop {
            self.set(x, y, c);
            if x == x1 && y == y1 {
                break;
            }
            let e2 = 2 * err;
            if e2 >= dy {
                err += dy;
                x += sx;
            }
            if e2 <= dx {
                err += dx;
                y += sy;
            }
        }
    }
    fn text(&mut self, x: i64, y: i64, s: &str, scale: i64) {
        let mut cx = x;
        for ch in s.chars() {
            if let Some((_, g)) = GLYPHS.iter().find(|(c, _)| *c == ch) {
                for (row, bits) in g.iter().enumerate() {
                    for col in 0..3 {
                        if bits & (0b100 >> col) != 0 {
                            for sy in 0..scale {
                                for sx in 0..scale {
                                    self.set(
                                        cx + col * scale + sx,
                                        y + row as i64 * scale + sy,
                                        [0, 0, 0],
                                    );
                                }
                            }
                        }
                    }
                }
            }
            cx += 4 * scale;
        }
    }
}

fn text_width(s: &str, scale: i64) -> i64 {
    s.chars().count() as i64 * 4 * scale - scale
}

/// A "nice" tick step (1, 2 or 5 × 10^k) giving about `n` ticks over `span`.
fn tick_step(span: f64, n: f64) -> f64 {
    let raw = (span / n).max(f64::MIN_POSITIVE);
    let mag = 10f64.powf(raw.log10().floor());
    let r = raw / mag;
    mag * if r < 1.5 {
        1.0
    } else if r < 3.5 {
        2.0
    } else if r < 7.5 {
        5.0
    } else {
        10.0
    }
}

/// A short label: 1500 → "1.5k", 2000000 → "2M".
#[must_use]
pub fn short_number(v: f64) -> String {
    let (d, suffix) = if v.abs() >= 1e9 {
        (1e9, "G")
    } else if v.abs() >= 1e6 {
        (1e6, "M")
    } else if v.abs() >= 1e3 {
        (1e3, "k")
    } else {
        (1.0, "")
    };
    let x = v / d;
    let s = if (x - x.round()).abs() < 1e-9 {
        format!("{}", x.round() as i64)
    } else {
        format!("{x:.1}")
    };
    format!("{s}{suffix}")
}

/// Draws the points `(x, y)` as a polyline with axes, ticks and labels ("steps",
/// "area") into an RGB PNG of `width × height` pixels. O(points + pixels).
///
/// # Errors
/// [`PlotError::Size`] for a size outside 64..=8192; encoder errors.
pub fn line_plot_png(points: &[(f64, f64)], width: u32, height: u32) -> Result<Vec<u8>, PlotError> {
    if !(64..=8192).contains(&width) || !(64..=8192).contains(&height) {
        return Err(PlotError::Size(width, height));
    }
    let mut cv = Canvas {
        w: width,
        h: height,
        px: vec![255; 3 * width as usize * height as usize],
    };
    let (w, h) = (i64::from(width), i64::from(height));
    let scale = if width >= 480 { 2 } else { 1 };
    let (left, right, top, bottom) = (14 * scale + 36 * scale, 10 * scale, 10 * scale, 24 * scale);
    let (x0, x1, y0, y1) = (left, w - right, h - bottom, top);
    let finite: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .filter(|p| p.0.is_finite() && p.1.is_finite())
        .collect();
    let (mut xmin, mut xmax, mut ymin, mut ymax) = (0.0f64, 1.0f64, 0.0f64, 1.0f64);
    if let Some(&(fx, _)) = finite.first() {
        xmin = fx;
        xmax = fx;
        ymax = 1.0;
        for &(x, y) in &finite {
            xmin = xmin.min(x);
            xmax = xmax.max(x);
            ymin = ymin.min(y);
            ymax = ymax.max(y);
        }
    }
    if xmax <= xmin {
        xmax = xmin + 1.0;
    }
    let ystep = tick_step(ymax - ymin, 5.0);
    ymax = (ymax / ystep).ceil() * ystep;
    let px = |x: f64| x0 + ((x - xmin) / (xmax - xmin) * (x1 - x0) as f64).round() as i64;
    let py = |y: f64| y0 - ((y - ymin) / (ymax - ymin) * (y0 - y1) as f64).round() as i64;
    let grid = [225, 225, 225];
    let xstep = tick_step(xmax - xmin, 5.0);
    let mut t = (xmin / xstep).ceil() * xstep;
    while t <= xmax + 1e-9 * xstep {
        let x = px(t);
        cv.line(x, y0, x, y1, grid);
        let label = short_number(t);
        cv.text(
            x - text_width(&label, scale) / 2,
            y0 + 4 * scale,
            &label,
            scale,
        );
        t += xstep;
    }
    let mut t = (ymin / ystep).ceil() * ystep;
    while t <= ymax + 1e-9 * ystep {
        let y = py(t);
        cv.line(x0, y, x1, y, grid);
        let label = short_number(t);
        cv.text(
            x0 - 3 * scale - text_width(&label, scale),
            y - 2 * scale,
            &label,
            scale,
        );
        t += ystep;
    }
    let black = [0, 0, 0];
    cv.line(x0, y0, x1, y0, black);
    cv.line(x0, y0, x0, y1, black);
    cv.text(
        x1 - text_width("steps", scale),
        y0 + 14 * scale,
        "steps",
        scale,
    );
    cv.text(2 * scale, y1, "area", scale);
    let blue = [31, 90, 200];
    for pair in finite.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        cv.line(px(a.0), py(a.1), px(b.0), py(b.1), blue);
    }
    if finite.len() == 1 {
        cv.set(px(finite[0].0), py(finite[0].1), blue);
    }
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, width, height);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut writer = enc.write_header()?;
        writer.write_image_data(&cv.px)?;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_and_ticks() {
        assert_eq!(short_number(1500.0), "1.5k");
        assert_eq!(short_number(2e6), "2M");
        assert_eq!(short_number(40.0), "40");
        assert_eq!(tick_step(1000.0, 5.0), 200.0);
    }

    #[test]
    fn decodes_and_has_ink() {
        let pts: Vec<(f64, f64)> = (0..100)
            .map(|i| (f64::from(i) * 10.0, f64::from(i * i)))
            .collect();
        let png_bytes = line_plot_png(&pts, 400, 300).unwrap();
        let dec = png::Decoder::new(std::io::Cursor::new(png_bytes));
        let mut r = dec.read_info().unwrap();
        let mut buf = vec![0; r.output_buffer_size()];
        let info = r.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height), (400, 300));
        let blue = buf.chunks(3).filter(|p| p == &[31, 90, 200]).count();
        assert!(blue > 300, "{blue}");
        assert!(line_plot_png(&pts, 10, 10).is_err());
    }
}
