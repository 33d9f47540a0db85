//! Pictures in: a PNG or JPEG file read as grey levels (colour by Rec. 601
//! luma, as OpenCV's `cvtColor`; transparency laid over white paper), then
//! cut and scaled by area averaging.

use std::path::Path;

/// A grey picture: 0 is black, 1 white; row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct Gray {
    pub width: usize,
    pub height: usize,
    pub pixels: Vec<f32>,
}

impl Gray {
    pub fn new(width: usize, height: usize, level: f32) -> Gray {
        Gray {
            width,
            height,
            pixels: vec![level; width * height],
        }
    }

    /// Reads a PNG or JPEG file; the error names the file and what is wrong.
    pub fn open(path: &Path) -> Result<Gray, String> {
        let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
        Gray::decode(&bytes).map_err(|e| format!("{}: {e}", path.display()))
    }

    /// PNG or JPEG bytes, told apart by their signature.
    pub fn decode(bytes: &[u8]) -> Result<Gray, String> {
        let gray = if bytes.starts_with(b"\x89PNG") {
            decode_png(bytes)?
        } else if bytes.starts_with(&[0xFF, 0xD8]) {
            decode_jpeg(bytes)?
        } else {
            return Err("not a PNG or JPEG image".into());
        };
        if gray.width == 0 || gray.height == 0 {
            return Err("the image has no pixels".into());
        }
        Ok(gray)
    }

    pub fn at(&self, x: usize, y: usize) -> f32 {
        self.pixels[y * self.width + x]
    }

    /// The centred square whose side is the shorter side.
    pub fn centre_square(&self) -> Gray {
        let side = self.width.min(self.height);
        let (x0, y0) = ((self.width - side) / 2, (self.height - side) / 2);
        let mut out = Gray::new(side, side, 1.0);
        for y in 0..side {
            let row = (y0 + y) * self.width + x0;
            out.pixels[y * side..][..side].copy_from_slice(&self.pixels[row..][..side]);
        }
        out
    }

    /// Scaled to `width` × `height`: each new pixel the area-weighted mean
    /// of the old pixels under it.
    pub fn resized(&self, width: usize, height: usize) -> Gray {
        let across = area_weights(self.width, width);
        let down = area_weights(self.height, height);
        // Rows first, then columns: separable.
        let mut rows = vec![0.0f32; self.height * width];
        for y in 0..self.height {
            let src = &self.pixels[y * self.width..][..self.width];
            for (x, w) in across.iter().enumerate() {
                rows[y * width + x] = w.iter().map(|&(i, k)| src[i] * k).sum();
            }
        }
        let mut out = Gray::new(width, height, 0.0);
        for (y, w) in down.iter().enumerate() {
            for x in 0..width {
                out.pixels[y * width + x] = w.iter().map(|&(i, k)| rows[i * width + x] * k).sum();
            }
        }
        out
    }
}

/// For each of `to` cells over `from` cells: the old cells under it and
/// their share of its width (summing to 1).
fn area_weights(from: usize, to: usize) -> Vec<Vec<(usize, f32)>> {
    let step = from as f64 / to as f64;
    (0..to)
        .map(|i| {
            let (a, b) = (i as f64 * step, (i + 1) as f64 * step);
            let first = a.floor() as usize;
            let last = (b.ceil() as usize).min(from);
            (first..last)
                .filter_map(|j| {
                    let overlap = b.min(j as f64 + 1.0) - a.max(j as f64);
                    (overlap > 0.0).then_some((j, (overlap / step) as f32))
                })
                .collect()
        })
        .collect()
}

/// Rec. 601 luma of 8-bit RGB, 0–1.
fn luma(r: u8, g: u8, b: u8) -> f32 {
    (0.299 * f32::from(r) + 0.587 * f32::from(g) + 0.114 * f32::from(b)) / 255.0
}

/// A level seen through `alpha` (0–255) over white.
fn over_white(level: f32, alpha: u8) -> f32 {
    let a = f32::from(alpha) / 255.0;
    level * a + (1.0 - a)
}

fn decode_png(bytes: &[u8]) -> Result<Gray, String> {
    let mut decoder = png::Decoder::new(bytes);
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder.read_info().map_err(|e| format!("PNG: {e}"))?;
    let mut buf = vec![0; reader.output_buffer_size()];
    let frame = reader
        .next_frame(&mut buf)
        .map_err(|e| format!("PNG: {e}"))?;
    let data = &buf[..frame.buffer_size()];
    let pixels = match frame.color_type {
        png::ColorType::Grayscale => data.iter().map(|&v| f32::from(v) / 255.0).collect(),
        png::ColorType::GrayscaleAlpha => data
            .chunks_exact(2)
            .map(|p| over_white(f32::from(p[0]) / 255.0, p[1]))
            .collect(),
        png::ColorType::Rgb => data
            .chunks_exact(3)
            .map(|p| luma(p[0], p[1], p[2]))
            .collect(),
        png::ColorType::Rgba => data
            .chunks_exact(4)
            .map(|p| over_white(luma(p[0], p[1], p[2]), p[3]))
            .collect(),
        other => return Err(format!("PNG: unexpected colour type {other:?}")),
    };
    Ok(Gray {
        width: frame.width as usize,
        height: frame.height as usize,
        pixels,
    })
}

fn decode_jpeg(bytes: &[u8]) -> Result<Gray, String> {
    let mut decoder = jpeg_decoder::Decoder::new(bytes);
    let data = decoder.decode().map_err(|e| format!("JPEG: {e}"))?;
    let info = decoder.info().ok_or("JPEG: no image information")?;
    use jpeg_decoder::PixelFormat;
    let pixels = match info.pixel_format {
        PixelFormat::L8 => data.iter().map(|&v| f32::from(v) / 255.0).collect(),
        PixelFormat::L16 => data
            .chunks_exact(2)
            .map(|p| f32::from(u16::from_be_bytes([p[0], p[1]])) / 65535.0)
            .collect(),
        PixelFormat::RGB24 => data
            .chunks_exact(3)
            .map(|p| luma(p[0], p[1], p[2]))
            .collect(),
        PixelFormat::CMYK32 => data
            .chunks_exact(4)
            .map(|p| {
                // Adobe's inverted CMYK, as JPEG files store it.
                let k = f32::from(p[3]) / 255.0;
                let c = |v: u8| (f32::from(v) * k) as u8;
                luma(c(p[0]), c(p[1]), c(p[2]))
            })
            .collect(),
    };
    Ok(Gray {
        width: usize::from(info.width),
        height: usize::from(info.height),
        pixels,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn examples() -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/images")
    }

    #[test]
    fn the_example_images_read() {
        let camera = Gray::open(&examples().join("camera.jpg")).unwrap();
        assert_eq!((camera.width, camera.height), (512, 512));
        let horse = Gray::open(&examples().join("horse.png")).unwrap();
        assert_eq!((horse.width, horse.height), (400, 328));
        // Transparent ground reads as white paper, the horse as black.
        assert!(horse.at(2, 2) > 0.99, "{}", horse.at(2, 2));
        assert!(horse.at(200, 150) < 0.05, "{}", horse.at(200, 150));
        let astronaut = Gray::open(&examples().join("astronaut.jpg")).unwrap();
        let mean = astronaut.pixels.iter().sum::<f32>() / astronaut.pixels.len() as f32;
        assert!((0.2..0.8).contains(&mean), "{mean}");
    }

    #[test]
    fn unreadable_files_say_why() {
        let missing = Gray::open(Path::new("/nonexistent/x.png")).unwrap_err();
        assert!(missing.starts_with("/nonexistent/x.png: "), "{missing}");
        assert_eq!(
            Gray::decode(b"GIF89a").unwrap_err(),
            "not a PNG or JPEG image"
        );
        let broken = Gray::decode(b"\x89PNG\r\n\x1a\n\0\0").unwrap_err();
        assert!(broken.starts_with("PNG: "), "{broken}");
        let broken = Gray::decode(&[0xFF, 0xD8, 0xFF, 0x00]).unwrap_err();
        assert!(broken.starts_with("JPEG: "), "{broken}");
    }

    #[test]
    fn squares_and_area_averages() {
        let mut g = Gray::new(4, 2, 0.0);
        g.pixels = vec![0.0, 1.0, 0.5, 0.25, 1.0, 1.0, 0.0, 0.0];
        let sq = g.centre_square();
        assert_eq!(sq.pixels, vec![1.0, 0.5, 1.0, 0.0]);
        let half = g.resized(2, 1);
        assert_eq!(half.pixels, vec![0.75, 0.1875]);
        // Area averaging keeps the mean at any scale.
        let big = g.resized(7, 3);
        let mean = |g: &Gray| g.pixels.iter().sum::<f32>() / g.pixels.len() as f32;
        assert!((mean(&big) - mean(&g)).abs() < 1e-5);
    }
}
