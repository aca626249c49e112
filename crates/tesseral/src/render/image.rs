//! The image type and its PNG output.

use std::io::Write;
use std::path::Path;

use crate::io::{write_atomic, FormatError};

/// An RGB image, rows from the top.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Image {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// The pixels, row-major from the top-left.
    pub pixels: Vec<[u8; 3]>,
}

impl Image {
    /// A `width × height` image filled with `colour`.
    #[must_use]
    pub fn new(width: usize, height: usize, colour: [u8; 3]) -> Self {
        Self {
            width,
            height,
            pixels: vec![colour; width * height],
        }
    }

    /// The pixel at column `x`, row `y`.
    #[must_use]
    pub fn get(&self, x: usize, y: usize) -> [u8; 3] {
        self.pixels[y * self.width + x]
    }

    /// Copies `other` into this image with its top-left corner at `(x, y)`, clipped.
    pub fn blit(&mut self, other: &Image, x: usize, y: usize) {
        for row in 0..other.height {
            let ty = y + row;
            if ty >= self.height {
                break;
            }
            for col in 0..other.width {
                let tx = x + col;
                if tx >= self.width {
                    break;
                }
                self.pixels[ty * self.width + tx] = other.pixels[row * other.width + col];
            }
        }
    }

    /// Encodes the image as PNG (8-bit RGB).
    ///
    /// # Errors
    /// The writer's I/O errors.
    pub fn encode_png(&self, w: &mut dyn Write) -> std::io::Result<()> {
        let mut enc = png::Encoder::new(w, self.width as u32, self.height as u32);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_compression(png::Compression::Best);
        let mut writer = enc.write_header().map_err(std::io::Error::other)?;
        let data: Vec<u8> = self.pixels.iter().flatten().copied().collect();
        writer
            .write_image_data(&data)
            .map_err(std::io::Error::other)?;
        writer.finish().map_err(std::io::Error::other)
    }

    /// Writes the image as a PNG file, atomically (temporary name, then rename).
    ///
    /// # Errors
    /// [`FormatError::Io`] naming the file.
    pub fn write_png(&self, path: &Path) -> Result<(), FormatError> {
        write_atomic(path, |w| self.encode_png(w))
    }
}
