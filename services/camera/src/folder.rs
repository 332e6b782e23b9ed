//! The camera's second source: a folder of PNG/JPEG images played as frames, decoded straight
//! into the loaned shared-memory slice when their pixel format is the frame's.

use std::path::{Path, PathBuf};

use anyhow::Context;
use image::{ColorType, DynamicImage, ImageDecoder, ImageReader};

use harvey_msgs::Encoding;

/// The images of a folder, in name order, all of one size.
pub struct Folder {
    files: Vec<PathBuf>,
    pub width_px: u32,
    pub height_px: u32,
    pub encoding: Encoding,
}

fn decoder(path: &Path) -> anyhow::Result<impl ImageDecoder> {
    ImageReader::open(path)
        .with_context(|| format!("{}: cannot open", path.display()))?
        .with_guessed_format()
        .with_context(|| format!("{}: cannot read", path.display()))?
        .into_decoder()
        .with_context(|| format!("{}: not a PNG or JPEG image", path.display()))
}

impl Folder {
    /// Lists `*.png`, `*.jpg` and `*.jpeg` in `dir`; the first fixes size and encoding (grey
    /// images play as mono8, everything else as rgb8).
    pub fn open(dir: &Path) -> anyhow::Result<Self> {
        let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
            .with_context(|| format!("{}: cannot list", dir.display()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                p.extension()
                    .and_then(|e| e.to_str())
                    .is_some_and(|e| ["png", "jpg", "jpeg"].contains(&e.to_ascii_lowercase().as_str()))
            })
            .collect();
        files.sort();
        let first = files.first().with_context(|| format!("{}: no PNG or JPEG images", dir.display()))?;
        let (width_px, height_px, colour) = {
            let d = decoder(first)?;
            let (w, h) = d.dimensions();
            (w, h, d.color_type())
        };
        let encoding = if colour == ColorType::L8 { Encoding::Mono8 } else { Encoding::Rgb8 };
        Ok(Self { files, width_px, height_px, encoding })
    }

    /// How many images the folder holds (at least one).
    pub fn count(&self) -> usize {
        self.files.len()
    }

    pub fn frame_bytes(&self) -> usize {
        (self.width_px * self.height_px * self.encoding.bytes_per_pixel()) as usize
    }

    /// Decodes image `i` into `out` (`frame_bytes()` long).
    pub fn decode_into(&self, i: usize, out: &mut [u8]) -> anyhow::Result<()> {
        let path = &self.files[i % self.files.len()];
        let d = decoder(path)?;
        let (w, h) = d.dimensions();
        anyhow::ensure!(
            (w, h) == (self.width_px, self.height_px),
            "{}: {w}x{h}, but the folder's frames are {}x{}",
            path.display(),
            self.width_px,
            self.height_px
        );
        let native = match self.encoding {
            Encoding::Mono8 => ColorType::L8,
            Encoding::Rgb8 => ColorType::Rgb8,
        };
        if d.color_type() == native {
            // Straight into shared memory: no intermediate buffer.
            return d.read_image(out).with_context(|| format!("{}: corrupt image", path.display()));
        }
        let img =
            DynamicImage::from_decoder(d).with_context(|| format!("{}: corrupt image", path.display()))?;
        match self.encoding {
            Encoding::Mono8 => out.copy_from_slice(img.to_luma8().as_raw()),
            Encoding::Rgb8 => out.copy_from_slice(img.to_rgb8().as_raw()),
        }
        Ok(())
    }
}
