//! Grey images read in place (a frame's bytes in shared memory, or an owned buffer), windows on
//! them, and the errors a bad request gets.

/// What is wrong with a request; the service publishes it as an error result.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum VisionError {
    #[error("window {0} lies outside the {1}x{2} image")]
    WindowOutside(Rect, usize, usize),
    #[error("the template is empty")]
    EmptyTemplate,
    #[error("a {0}x{1} template does not fit in window {2}")]
    TemplateTooLarge(usize, usize, Rect),
    #[error("image {width}x{height} with stride {stride} does not fit in {bytes} bytes")]
    BadImage { width: usize, height: usize, stride: usize, bytes: usize },
    #[error("bad parameter: {0}")]
    BadParameter(String),
}

/// A rectangle of pixels, `[x0, x1) x [y0, y1)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Rect {
    pub x0: usize,
    pub y0: usize,
    pub x1: usize,
    pub y1: usize,
}

impl std::fmt::Display for Rect {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "[{}, {}) x [{}, {})", self.x0, self.x1, self.y0, self.y1)
    }
}

impl Rect {
    pub const fn new(x0: usize, y0: usize, x1: usize, y1: usize) -> Self {
        Self { x0, y0, x1, y1 }
    }

    /// A window from floating-point pixel bounds (an Expecter window), rounded outwards and
    /// clipped to a `width x height` image; `None` when nothing of it is inside.
    pub fn from_f32(w: [f32; 4], width: usize, height: usize) -> Option<Self> {
        if !w.iter().all(|v| v.is_finite()) {
            return None;
        }
        let clip = |v: f32, max: usize| (v.max(0.0) as usize).min(max);
        let r = Self::new(
            clip(w[0].floor(), width),
            clip(w[1].floor(), height),
            clip(w[2].ceil(), width),
            clip(w[3].ceil(), height),
        );
        (!r.is_empty()).then_some(r)
    }

    pub fn width(&self) -> usize {
        self.x1.saturating_sub(self.x0)
    }

    pub fn height(&self) -> usize {
        self.y1.saturating_sub(self.y0)
    }

    pub fn is_empty(&self) -> bool {
        self.width() == 0 || self.height() == 0
    }

    pub fn contains(&self, x: usize, y: usize) -> bool {
        (self.x0..self.x1).contains(&x) && (self.y0..self.y1).contains(&y)
    }

    /// The window itself if it is non-empty and lies inside a `width x height` image.
    pub fn inside(self, width: usize, height: usize) -> Result<Self, VisionError> {
        if self.is_empty() || self.x1 > width || self.y1 > height {
            return Err(VisionError::WindowOutside(self, width, height));
        }
        Ok(self)
    }
}

/// A grey image borrowed in place: `height` rows of `width` bytes, `stride` bytes apart.
#[derive(Debug, Clone, Copy)]
pub struct Gray<'a> {
    pub width: usize,
    pub height: usize,
    pub stride: usize,
    pub data: &'a [u8],
}

impl<'a> Gray<'a> {
    pub fn new(data: &'a [u8], width: usize, height: usize, stride: usize) -> Result<Self, VisionError> {
        let needed = if height == 0 { 0 } else { (height - 1) * stride + width };
        if width == 0 || height == 0 || stride < width || data.len() < needed {
            return Err(VisionError::BadImage { width, height, stride, bytes: data.len() });
        }
        Ok(Self { width, height, stride, data })
    }

    /// Row `y`, `width` bytes.
    #[inline]
    pub fn row(&self, y: usize) -> &'a [u8] {
        &self.data[y * self.stride..y * self.stride + self.width]
    }

    #[inline]
    pub fn at(&self, x: usize, y: usize) -> u8 {
        self.data[y * self.stride + x]
    }

    pub fn full(&self) -> Rect {
        Rect::new(0, 0, self.width, self.height)
    }
}

/// An owned grey image (templates, test frames, pyramid levels).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct GrayBuf {
    pub width: usize,
    pub height: usize,
    pub data: Vec<u8>,
}

impl GrayBuf {
    pub fn new(width: usize, height: usize) -> Self {
        Self { width, height, data: vec![0; width * height] }
    }

    /// An image whose pixel `(x, y)` is `f(x, y)`.
    pub fn from_fn(width: usize, height: usize, f: impl Fn(usize, usize) -> u8) -> Self {
        let mut data = Vec::with_capacity(width * height);
        for y in 0..height {
            data.extend((0..width).map(|x| f(x, y)));
        }
        Self { width, height, data }
    }

    pub fn view(&self) -> Gray<'_> {
        Gray { width: self.width, height: self.height, stride: self.width, data: &self.data }
    }

    /// Copies `r` of `img` out.
    pub fn crop(img: &Gray<'_>, r: Rect) -> Result<Self, VisionError> {
        let mut out = Self::default();
        out.crop_from(img, r)?;
        Ok(out)
    }

    /// Copies `r` of `img` into this buffer, reusing its memory.
    pub fn crop_from(&mut self, img: &Gray<'_>, r: Rect) -> Result<(), VisionError> {
        let r = r.inside(img.width, img.height)?;
        (self.width, self.height) = (r.width(), r.height());
        self.data.clear();
        for y in r.y0..r.y1 {
            self.data.extend_from_slice(&img.row(y)[r.x0..r.x1]);
        }
        Ok(())
    }
}
