//! [`ImageBuf`]: an interleaved, row-major pixel buffer (`f32` for radiance, `u8`/`u16` for camera
//! frames).

/// An image as a row-major, channel-interleaved buffer: the sample of channel `c` of pixel `(x, y)`
/// is `data[(y * width + x) * channels + c]`.
#[derive(Debug, Clone, PartialEq)]
pub struct ImageBuf<T> {
    width: usize,
    height: usize,
    channels: usize,
    data: Vec<T>,
}

/// The buffer's length does not match `width × height × channels`, or a dimension is zero.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "image buffer of {len} samples does not fit {width}×{height} pixels × {channels} channels \
     (dimensions must be non-zero and the buffer exactly their product)"
)]
pub struct ShapeError {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Channels per pixel.
    pub channels: usize,
    /// Number of samples given.
    pub len: usize,
}

impl<T: Copy> ImageBuf<T> {
    /// Wraps `data` (row-major, interleaved) as a `width × height` image with `channels` channels.
    ///
    /// # Errors
    /// [`ShapeError`] if a dimension is zero or `data.len() != width * height * channels`.
    pub fn new(
        width: usize,
        height: usize,
        channels: usize,
        data: Vec<T>,
    ) -> Result<Self, ShapeError> {
        let expected = width
            .checked_mul(height)
            .and_then(|n| n.checked_mul(channels));
        if width == 0 || height == 0 || channels == 0 || expected != Some(data.len()) {
            return Err(ShapeError {
                width,
                height,
                channels,
                len: data.len(),
            });
        }
        Ok(Self {
            width,
            height,
            channels,
            data,
        })
    }

    /// An image filled with `value`.
    ///
    /// # Errors
    /// [`ShapeError`] if a dimension is zero or the size overflows.
    pub fn filled(
        width: usize,
        height: usize,
        channels: usize,
        value: T,
    ) -> Result<Self, ShapeError> {
        let len = width
            .checked_mul(height)
            .and_then(|n| n.checked_mul(channels))
            .ok_or(ShapeError {
                width,
                height,
                channels,
                len: 0,
            })?;
        Self::new(width, height, channels, vec![value; len])
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// Channels per pixel (1 for grey, 3 for RGB).
    pub fn channels(&self) -> usize {
        self.channels
    }

    /// All samples, row-major and interleaved.
    pub fn data(&self) -> &[T] {
        &self.data
    }

    /// All samples, mutable.
    pub fn data_mut(&mut self) -> &mut [T] {
        &mut self.data
    }

    /// Consumes the image and returns its samples.
    pub fn into_data(self) -> Vec<T> {
        self.data
    }

    /// The samples of pixel `(x, y)`, or `None` outside the image.
    pub fn pixel(&self, x: usize, y: usize) -> Option<&[T]> {
        (x < self.width && y < self.height).then(|| {
            let start = (y * self.width + x) * self.channels;
            &self.data[start..start + self.channels]
        })
    }

    /// Row `y` (all its pixels' samples), or `None` outside the image.
    pub fn row(&self, y: usize) -> Option<&[T]> {
        (y < self.height).then(|| {
            let stride = self.width * self.channels;
            &self.data[y * stride..(y + 1) * stride]
        })
    }

    /// True if both images have the same width, height and channel count.
    pub fn same_shape<U: Copy>(&self, other: &ImageBuf<U>) -> bool {
        self.width == other.width && self.height == other.height && self.channels == other.channels
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_mismatched_length_and_zero_dimensions() {
        assert!(ImageBuf::new(2, 2, 3, vec![0u8; 11]).is_err());
        assert!(ImageBuf::new(0, 2, 3, Vec::<u8>::new()).is_err());
        assert!(ImageBuf::new(2, 2, 3, vec![0u8; 12]).is_ok());
    }

    #[test]
    fn pixel_indexing_is_row_major_interleaved() {
        let data: Vec<u16> = (0..2 * 3 * 3).collect();
        let img = ImageBuf::new(3, 2, 3, data).unwrap();
        assert_eq!(img.pixel(1, 1), Some(&[12u16, 13, 14][..]));
        assert_eq!(img.pixel(3, 0), None);
        assert_eq!(img.row(1).unwrap().len(), 9);
    }
}
