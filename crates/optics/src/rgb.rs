//! Per-channel values: [`Channel`] names a linear-sRGB channel, [`Rgb`] holds one value per channel
//! by name (`r`, `g`, `b`), never by position in a `Vec`.
//!
//! In files an `Rgb<T>` is `{"r": …, "g": …, "b": …}` (the keys of `result.json`'s `channels` and of
//! `spectro --json`).

use std::fmt;
use std::ops::{Index, IndexMut};

use serde::{Deserialize, Serialize};

/// A linear-sRGB colour channel (IEC 61966-2-1; D65, 2° observer). In files, its [`Channel::key`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Channel {
    /// Red.
    R,
    /// Green.
    G,
    /// Blue.
    B,
}

impl Channel {
    /// The three channels in R, G, B order.
    pub const ALL: [Channel; 3] = [Channel::R, Channel::G, Channel::B];

    /// 0, 1, 2 for R, G, B (the order of image buffers and of [`Rgb::into_array`]).
    pub fn index(self) -> usize {
        match self {
            Channel::R => 0,
            Channel::G => 1,
            Channel::B => 2,
        }
    }

    /// `"R"`, `"G"`, `"B"`: the channel as people read it (messages, tables, plots).
    pub fn name(self) -> &'static str {
        match self {
            Channel::R => "R",
            Channel::G => "G",
            Channel::B => "B",
        }
    }

    /// `"r"`, `"g"`, `"b"`: the channel's key in files (`result.json`, CSV column suffixes).
    pub fn key(self) -> &'static str {
        match self {
            Channel::R => "r",
            Channel::G => "g",
            Channel::B => "b",
        }
    }
}

impl fmt::Display for Channel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// One value per linear-sRGB channel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
pub struct Rgb<T> {
    /// Red.
    pub r: T,
    /// Green.
    pub g: T,
    /// Blue.
    pub b: T,
}

impl<T> Rgb<T> {
    /// The value `f(c)` for every channel c.
    pub fn from_fn(mut f: impl FnMut(Channel) -> T) -> Self {
        Self {
            r: f(Channel::R),
            g: f(Channel::G),
            b: f(Channel::B),
        }
    }

    /// From `[r, g, b]`.
    pub fn from_array([r, g, b]: [T; 3]) -> Self {
        Self { r, g, b }
    }

    /// `[r, g, b]`.
    pub fn into_array(self) -> [T; 3] {
        [self.r, self.g, self.b]
    }

    /// Borrows each value.
    pub fn as_ref(&self) -> Rgb<&T> {
        Rgb {
            r: &self.r,
            g: &self.g,
            b: &self.b,
        }
    }

    /// `f` applied to each value.
    pub fn map<U>(self, mut f: impl FnMut(T) -> U) -> Rgb<U> {
        Rgb {
            r: f(self.r),
            g: f(self.g),
            b: f(self.b),
        }
    }

    /// `f(channel, value)` for each channel.
    pub fn map_with_channel<U>(self, mut f: impl FnMut(Channel, T) -> U) -> Rgb<U> {
        Rgb {
            r: f(Channel::R, self.r),
            g: f(Channel::G, self.g),
            b: f(Channel::B, self.b),
        }
    }

    /// The values of `self` and `other` paired by channel.
    pub fn zip<U>(self, other: Rgb<U>) -> Rgb<(T, U)> {
        Rgb {
            r: (self.r, other.r),
            g: (self.g, other.g),
            b: (self.b, other.b),
        }
    }

    /// The values in R, G, B order.
    pub fn iter(&self) -> std::array::IntoIter<&T, 3> {
        [&self.r, &self.g, &self.b].into_iter()
    }

    /// (channel, value) in R, G, B order.
    pub fn iter_channels(&self) -> std::array::IntoIter<(Channel, &T), 3> {
        [
            (Channel::R, &self.r),
            (Channel::G, &self.g),
            (Channel::B, &self.b),
        ]
        .into_iter()
    }
}

impl<T, E> Rgb<Result<T, E>> {
    /// All three values, or the first error in R, G, B order.
    ///
    /// # Errors
    /// The first channel's error.
    pub fn transpose(self) -> Result<Rgb<T>, E> {
        Ok(Rgb {
            r: self.r?,
            g: self.g?,
            b: self.b?,
        })
    }
}

impl<T> Rgb<Option<T>> {
    /// All three values, or `None` when any channel has none.
    pub fn transpose(self) -> Option<Rgb<T>> {
        Some(Rgb {
            r: self.r?,
            g: self.g?,
            b: self.b?,
        })
    }
}

impl<T> Index<Channel> for Rgb<T> {
    type Output = T;
    fn index(&self, c: Channel) -> &T {
        match c {
            Channel::R => &self.r,
            Channel::G => &self.g,
            Channel::B => &self.b,
        }
    }
}

impl<T> IndexMut<Channel> for Rgb<T> {
    fn index_mut(&mut self, c: Channel) -> &mut T {
        match c {
            Channel::R => &mut self.r,
            Channel::G => &mut self.g,
            Channel::B => &mut self.b,
        }
    }
}

impl<T> From<[T; 3]> for Rgb<T> {
    fn from(a: [T; 3]) -> Self {
        Self::from_array(a)
    }
}

impl<T> From<Rgb<T>> for [T; 3] {
    fn from(v: Rgb<T>) -> Self {
        v.into_array()
    }
}

impl<T> IntoIterator for Rgb<T> {
    type Item = T;
    type IntoIter = std::array::IntoIter<T, 3>;
    fn into_iter(self) -> Self::IntoIter {
        self.into_array().into_iter()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Channels know their position, their display name and their file key.
    #[test]
    fn channel_names_and_positions() {
        let names: Vec<_> = Channel::ALL.iter().map(|c| c.name()).collect();
        assert_eq!(names, ["R", "G", "B"]);
        let keys: Vec<_> = Channel::ALL.iter().map(|c| c.key()).collect();
        assert_eq!(keys, ["r", "g", "b"]);
        for (i, c) in Channel::ALL.into_iter().enumerate() {
            assert_eq!(c.index(), i);
            assert_eq!(c.to_string(), c.name());
        }
    }

    /// Indexing by channel, the array round trip and `from_fn` agree on which value is which.
    #[test]
    fn index_and_array_agree() {
        let mut v = Rgb::from_array([1.0, 2.0, 3.0]);
        assert_eq!((v.r, v.g, v.b), (1.0, 2.0, 3.0));
        assert_eq!(v[Channel::G], 2.0);
        v[Channel::B] = 5.0;
        assert_eq!(v.into_array(), [1.0, 2.0, 5.0]);
        let w = Rgb::from_fn(|c| c.index() * 10);
        assert_eq!(w, Rgb { r: 0, g: 10, b: 20 });
        for c in Channel::ALL {
            assert_eq!(w[c], c.index() * 10);
        }
        let arr: [usize; 3] = w.into();
        assert_eq!(Rgb::from(arr), w);
    }

    /// map, zip and the iterators keep R, G, B together and in order.
    #[test]
    fn map_zip_iter() {
        let a = Rgb::from_array([1, 2, 3]);
        let b = Rgb::from_array(["x", "y", "z"]);
        assert_eq!(a.map(|x| x * 2).into_array(), [2, 4, 6]);
        assert_eq!(a.zip(b).into_array(), [(1, "x"), (2, "y"), (3, "z")]);
        assert_eq!(a.iter().copied().collect::<Vec<_>>(), [1, 2, 3]);
        assert_eq!(a.into_iter().sum::<i32>(), 6);
        let tagged: Vec<_> = a.iter_channels().map(|(c, v)| (c.key(), *v)).collect();
        assert_eq!(tagged, [("r", 1), ("g", 2), ("b", 3)]);
        assert_eq!(
            a.map_with_channel(|c, v| format!("{c}{v}")).into_array(),
            ["R1", "G2", "B3"]
        );
        assert_eq!(a.as_ref().map(|x| *x + 1).into_array(), [2, 3, 4]);
    }

    /// Transpose: all or nothing, the first failing channel in R, G, B order.
    #[test]
    fn transpose_result_and_option() {
        let ok: Rgb<Result<i32, &str>> = Rgb::from_array([Ok(1), Ok(2), Ok(3)]);
        assert_eq!(ok.transpose(), Ok(Rgb::from_array([1, 2, 3])));
        let bad: Rgb<Result<i32, &str>> = Rgb::from_array([Ok(1), Err("g"), Err("b")]);
        assert_eq!(bad.transpose(), Err("g"));
        let some = Rgb::from_array([Some(1), Some(2), Some(3)]);
        assert_eq!(some.transpose(), Some(Rgb::from_array([1, 2, 3])));
        let none = Rgb::from_array([Some(1), None, Some(3)]);
        assert_eq!(none.transpose(), None);
    }

    /// JSON is keyed by channel name, as `result.json` writes channels.
    #[test]
    fn serde_by_name() {
        let v = Rgb::from_array([0.5, 0.25, 1.0]);
        let json = serde_json::to_string(&v).unwrap();
        assert_eq!(json, r#"{"r":0.5,"g":0.25,"b":1.0}"#);
        assert_eq!(serde_json::from_str::<Rgb<f64>>(&json).unwrap(), v);
        assert!(serde_json::from_str::<Rgb<f64>>(r#"{"r":1,"g":2}"#).is_err());
        assert_eq!(serde_json::to_string(&Channel::G).unwrap(), r#""g""#);
    }
}
