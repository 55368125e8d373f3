//! Inverse-CDF warps of pixel grids: a marginal CDF over rows and a
//! conditional CDF over the columns of each row ([`GridCdf`]), shared by the
//! lat-long env-map sampler ([`super::envmap::InverseCdf`]) and the planar
//! raster warp ([`RasterCdf`]). A warp maps `(u, v)` in `[0, 1)²` to a pixel
//! and a position inside it, monotonically in each coordinate, so it carries
//! the stratification of a low-discrepancy set (Sobol) over to the density.
//!
//! ```
//! use tessera::baselines::cdf::GridCdf;
//! let cdf = GridCdf::new(2, 1, &[1.0, 3.0]).unwrap();
//! assert_eq!(cdf.locate([0.5, 0.5]).0, 1); // the heavier column
//! ```

use crate::density::plane::Raster;
use crate::Error;
use glam::DVec2;

/// Index `k` with `cdf[k] <= u < cdf[k + 1]` (never a zero-width entry).
#[inline]
pub(crate) fn search(cdf: &[f64], u: f64) -> usize {
    cdf[1..].partition_point(|&c| c <= u).min(cdf.len() - 2)
}

/// [`search`] for a `u` at or after the `u` that gave `from` (so the
/// answer is at least `from`): a galloping search forward from `from`,
/// steps 1, 2, 4, ... then a binary search inside the last step, so a
/// sorted run of `u` walks the CDF once, in order, touching
/// `O(log gap)` entries each. The same index as [`search`].
#[inline]
pub(crate) fn search_from(cdf: &[f64], from: usize, u: f64) -> usize {
    let last = cdf.len() - 2; // the largest index
    if from >= last || cdf[from + 1] > u {
        return from.min(last);
    }
    // the answer is in lo..=last; gallop until cdf[hi + 1] > u
    let (mut lo, mut step) = (from + 1, 1);
    let hi = loop {
        let hi = (lo + step - 1).min(last);
        if hi == last || cdf[hi + 1] > u {
            break hi;
        }
        lo = hi + 1;
        step *= 2;
    };
    (lo + cdf[lo + 1..=hi + 1].partition_point(|&c| c <= u)).min(last)
}

/// Running sums of `weights` divided by their total (`None` when it is 0),
/// with the last entry exactly 1.
pub(crate) fn normalised_cdf(weights: impl Iterator<Item = f64>) -> Option<Vec<f64>> {
    let mut cdf = vec![0.0];
    let mut sum = 0.0;
    for w in weights {
        sum += w;
        cdf.push(sum);
    }
    if sum <= 0.0 {
        return None;
    }
    cdf.iter_mut().for_each(|c| *c /= sum);
    *cdf.last_mut().expect("non-empty") = 1.0;
    Some(cdf)
}

/// Where `u` falls inside CDF entry `k`, in `[0, 1)`.
#[inline]
pub(crate) fn remainder(cdf: &[f64], k: usize, u: f64) -> f64 {
    let width = cdf[k + 1] - cdf[k];
    ((u - cdf[k]) / width).clamp(0.0, 1.0 - f64::EPSILON / 2.0)
}

/// Marginal (rows) and conditional (columns per row) CDFs of non-negative
/// pixel weights, row-major.
///
/// # Example
/// ```
/// use tessera::baselines::cdf::GridCdf;
/// let cdf = GridCdf::new(1, 2, &[0.0, 1.0]).unwrap();
/// assert_eq!(cdf.locate([0.0, 0.3]).1, 1); // row 0 weighs nothing
/// assert!(GridCdf::new(1, 1, &[0.0]).is_none());
/// ```
#[derive(Clone, Debug)]
pub struct GridCdf {
    width: usize,
    /// Over rows: `height + 1` entries.
    marginal: Vec<f64>,
    /// Over the columns of each row: `width + 1` entries per row (a zero
    /// row is never chosen and keeps a uniform CDF).
    conditional: Vec<f64>,
}

impl GridCdf {
    /// Builds the CDFs in one pass; `None` when every weight is zero.
    ///
    /// # Panics
    /// If `weights.len() != width * height`.
    ///
    /// # Example
    /// ```
    /// assert!(tessera::baselines::cdf::GridCdf::new(2, 2, &[1.0; 4]).is_some());
    /// ```
    pub fn new(width: usize, height: usize, weights: &[f64]) -> Option<Self> {
        assert_eq!(weights.len(), width * height, "one weight per pixel");
        let mut conditional = Vec::with_capacity(height * (width + 1));
        let mut row_weights = Vec::with_capacity(height);
        for row in weights.chunks(width) {
            row_weights.push(row.iter().sum::<f64>());
            let cdf = normalised_cdf(row.iter().copied())
                .unwrap_or_else(|| (0..=width).map(|k| k as f64 / width as f64).collect());
            conditional.extend(cdf);
        }
        let marginal = normalised_cdf(row_weights.into_iter())?;
        Some(GridCdf {
            width,
            marginal,
            conditional,
        })
    }

    /// The pixel (column `i`, row `j`) for `u = [u_row, u_column]` in
    /// `[0, 1)²` and where each number fell inside its CDF entry,
    /// `[t_column, t_row]` in `[0, 1)²` (uniform inside the pixel when `u`
    /// is uniform).
    ///
    /// # Example
    /// ```
    /// use tessera::baselines::cdf::GridCdf;
    /// let (i, j, t) = GridCdf::new(2, 2, &[1.0; 4]).unwrap().locate([0.75, 0.25]);
    /// assert_eq!((i, j), (0, 1));
    /// assert!((t[0] - 0.5).abs() < 1e-12 && (t[1] - 0.5).abs() < 1e-12);
    /// ```
    #[inline]
    pub fn locate(&self, u: [f64; 2]) -> (usize, usize, [f64; 2]) {
        let j = search(&self.marginal, u[0]);
        let row = &self.conditional[j * (self.width + 1)..(j + 1) * (self.width + 1)];
        let i = search(row, u[1]);
        (
            i,
            j,
            [remainder(row, i, u[1]), remainder(&self.marginal, j, u[0])],
        )
    }
}

/// Inverse-CDF warp of `[0, 1)²` onto a planar [`Raster`] density (pixel
/// `(col, row)` covers `[col/w, (col+1)/w) x [row/h, (row+1)/h)`).
///
/// # Example
/// ```
/// use tessera::{baselines::cdf::RasterCdf, density::plane::Raster};
/// let raster = Raster::new(2, 1, vec![0.0, 1.0], false).unwrap();
/// let p = RasterCdf::new(&raster).unwrap().warp(glam::DVec2::new(0.3, 0.6));
/// assert!(p.x >= 0.5);
/// ```
#[derive(Clone, Debug)]
pub struct RasterCdf {
    cdf: GridCdf,
    size: DVec2,
}

impl RasterCdf {
    /// Builds the CDFs of a raster density.
    ///
    /// # Errors
    /// [`Error::Density`] if every pixel is zero.
    ///
    /// # Example
    /// ```
    /// use tessera::{baselines::cdf::RasterCdf, density::plane::Raster};
    /// assert!(RasterCdf::new(&Raster::new(1, 1, vec![1.0], false).unwrap()).is_ok());
    /// ```
    pub fn new(raster: &Raster) -> Result<Self, Error> {
        let (w, h) = raster.dimensions();
        let cdf = GridCdf::new(w, h, raster.values()).ok_or_else(|| {
            Error::Density(
                "image".into(),
                "every pixel is zero: nothing to sample".into(),
            )
        })?;
        Ok(RasterCdf {
            cdf,
            size: DVec2::new(w as f64, h as f64),
        })
    }

    /// The point for `u` in `[0, 1)²` (`u.y` picks the row, `u.x` the column).
    ///
    /// # Example
    /// ```
    /// use tessera::{baselines::cdf::RasterCdf, density::plane::Raster};
    /// let cdf = RasterCdf::new(&Raster::new(2, 2, vec![1.0; 4], false).unwrap()).unwrap();
    /// let p = cdf.warp(glam::DVec2::new(0.3, 0.6));
    /// assert!((p.x - 0.3).abs() < 1e-12 && (p.y - 0.6).abs() < 1e-12);
    /// ```
    pub fn warp(&self, u: DVec2) -> DVec2 {
        let (i, j, [tx, ty]) = self.cdf.locate([u.y, u.x]);
        ((DVec2::new(i as f64 + tx, j as f64 + ty)) / self.size)
            .min(DVec2::splat(1.0 - f64::EPSILON / 2.0))
    }
}
