//! Reports of chosen measures: each measure's key and meaning, which of
//! them to compute, the size above which the O(N²) ones are skipped, and
//! progress while they run.
//!
//! ```
//! use tessera::baselines::spherical_fibonacci;
//! use tessera::metrics::{sphere, Options, SphereMeasure};
//! let options = Options {
//!     only: Some(vec![SphereMeasure::Separation]),
//!     ..Options::default()
//! };
//! let report = sphere::measure(&spherical_fibonacci(500), &options);
//! assert!(report[SphereMeasure::Separation] > 3.0);
//! assert_eq!(report.get(SphereMeasure::Covering), None);
//! ```

use crate::Error;
use serde::ser::{Serialize, SerializeMap, Serializer};
use std::sync::atomic::{AtomicU64, Ordering};

/// The default size limit of the O(N²) measures: on larger sets they are
/// skipped unless named in [`Options::only`].
///
/// ```
/// assert_eq!(tessera::metrics::PAIRS_UP_TO, 100_000);
/// ```
pub const PAIRS_UP_TO: usize = 100_000;

/// Progress callback of the long measures: stage, work done, work total
/// (called from worker threads, about a thousand times a stage).
pub type Progress<'a> = &'a (dyn Fn(&str, u64, u64) + Sync);

/// A measure of a point set, named in reports by its key.
///
/// ```
/// use tessera::metrics::{Measure, SphereMeasure};
/// assert_eq!(SphereMeasure::Covering.key(), "covering_radius_sqrt_n");
/// assert!(SphereMeasure::ALL.iter().any(|m| m.quadratic()));
/// ```
pub trait Measure: Copy + Eq + std::fmt::Debug + Send + Sync + 'static {
    /// Every measure of the domain, in report order.
    const ALL: &'static [Self];
    /// Its JSON key and table label.
    fn key(self) -> &'static str;
    /// What its value holds: definition, normalisation, units and
    /// reference values, in one paragraph.
    fn meaning(self) -> &'static str;
    /// Whether it costs O(N²) (skipped above [`Options::pairs_up_to`]
    /// unless named in [`Options::only`]).
    fn quadratic(self) -> bool;
}

/// Parses a comma-separated list of measure keys, refusing unknown keys
/// with the list of known ones.
///
/// ```
/// use tessera::metrics::{parse_measures, PlaneMeasure};
/// let only: Vec<PlaneMeasure> = parse_measures("l2_star_discrepancy, low_frequency_power").unwrap();
/// assert_eq!(only, [PlaneMeasure::L2Star, PlaneMeasure::LowFrequencyPower]);
/// let e = parse_measures::<PlaneMeasure>("separation").unwrap_err().to_string();
/// assert!(e.contains("'separation'") && e.contains("min_distance_over_hex_spacing"));
/// ```
pub fn parse_measures<M: Measure>(list: &str) -> Result<Vec<M>, Error> {
    list.split(',')
        .map(str::trim)
        .map(|key| {
            M::ALL
                .iter()
                .copied()
                .find(|m| m.key() == key)
                .ok_or_else(|| {
                    let known: Vec<_> = M::ALL.iter().map(|m| m.key()).collect();
                    Error::Request(format!(
                        "unknown measure '{key}'; the measures are {}",
                        known.join(", ")
                    ))
                })
        })
        .collect()
}

/// Which measures to compute and how to report progress.
///
/// ```
/// use tessera::metrics::{Options, SphereMeasure, PAIRS_UP_TO};
/// let options = Options::<SphereMeasure>::default();
/// assert!(options.only.is_none() && options.pairs_up_to == PAIRS_UP_TO);
/// ```
pub struct Options<'a, M> {
    /// The measures to compute (whatever N); `None`: all of them, the O(N²)
    /// ones only up to `pairs_up_to` points.
    pub only: Option<Vec<M>>,
    /// Above this many points the O(N²) measures not named in `only` are
    /// skipped (reported as `null`).
    pub pairs_up_to: usize,
    /// Told about the long stages.
    pub progress: Progress<'a>,
}

/// The progress callback that tells no one.
pub(crate) fn quiet(_: &str, _: u64, _: u64) {}

impl<M> Default for Options<'_, M> {
    fn default() -> Self {
        Options {
            only: None,
            pairs_up_to: PAIRS_UP_TO,
            progress: &quiet,
        }
    }
}

/// What a report does with one measure.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum Plan {
    /// Not asked for: absent from the report.
    Omit,
    /// Asked for by default but too costly at this size: `null`.
    Skip,
    Compute,
}

impl<M: Measure> Options<'_, M> {
    /// What happens to `measure` on `n` points.
    pub(crate) fn plan(&self, measure: M, n: usize) -> Plan {
        match &self.only {
            Some(only) if only.contains(&measure) => Plan::Compute,
            Some(_) => Plan::Omit,
            None if measure.quadratic() && n > self.pairs_up_to => Plan::Skip,
            None => Plan::Compute,
        }
    }

    /// Whether `measure` is computed on `n` points.
    pub(crate) fn computes(&self, measure: M, n: usize) -> bool {
        self.plan(measure, n) == Plan::Compute
    }
}

/// The measures of one point set: each asked-for measure's value, or
/// `None` where it was skipped for its cost. Serialises as one JSON object,
/// `n` first, then the keys in [`Measure::ALL`] order (skipped ones
/// `null`).
///
/// ```
/// use tessera::baselines::spherical_fibonacci;
/// use tessera::metrics::{sphere_report, SphereMeasure};
/// let r = sphere_report(&spherical_fibonacci(100));
/// assert_eq!(r.n(), 100);
/// assert!(r[SphereMeasure::MeshRatio] >= 1.0);
/// let json = serde_json::to_string(&r).unwrap();
/// assert!(json.starts_with("{\"n\":100,\"separation_sqrt_n\":"));
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Report<M> {
    n: usize,
    entries: Vec<(M, Option<f64>)>,
}

impl<M: Measure> Report<M> {
    /// The report `options` ask for on `n` points, `value` giving each
    /// measure computed (called once each, in [`Measure::ALL`] order).
    pub(crate) fn new(n: usize, options: &Options<M>, mut value: impl FnMut(M) -> f64) -> Self {
        let entries = M::ALL
            .iter()
            .filter_map(|&m| match options.plan(m, n) {
                Plan::Omit => None,
                Plan::Skip => Some((m, None)),
                Plan::Compute => Some((m, Some(value(m)))),
            })
            .collect();
        Report { n, entries }
    }

    /// Number of points.
    ///
    /// ```
    /// let r = tessera::metrics::plane_report(&[glam::DVec2::splat(0.5)]);
    /// assert_eq!(r.n(), 1);
    /// ```
    pub fn n(&self) -> usize {
        self.n
    }

    /// The value of `measure`, if it was computed.
    ///
    /// ```
    /// use tessera::metrics::{plane_report, PlaneMeasure};
    /// let r = plane_report(&[glam::DVec2::splat(0.5)]);
    /// assert_eq!(r.get(PlaneMeasure::MinDistance), Some(f64::INFINITY));
    /// ```
    pub fn get(&self, measure: M) -> Option<f64> {
        self.entries
            .iter()
            .find(|(m, _)| *m == measure)
            .and_then(|(_, v)| *v)
    }

    /// The measures asked for, in report order, with their values (`None`:
    /// skipped for its cost).
    ///
    /// ```
    /// use tessera::metrics::{sphere_report, Measure, SphereMeasure};
    /// let r = sphere_report(&[glam::DVec3::Z]);
    /// assert_eq!(r.entries().len(), SphereMeasure::ALL.len());
    /// ```
    pub fn entries(&self) -> &[(M, Option<f64>)] {
        &self.entries
    }

    /// The measures skipped for their cost.
    ///
    /// ```
    /// use tessera::baselines::spherical_fibonacci;
    /// use tessera::metrics::{sphere, Options, SphereMeasure};
    /// let options = Options { pairs_up_to: 10, ..Options::default() };
    /// let r = sphere::measure(&spherical_fibonacci(50), &options);
    /// let skipped: Vec<_> = r.skipped().collect();
    /// assert_eq!(skipped, [SphereMeasure::CapDiscrepancy, SphereMeasure::Energy]);
    /// ```
    pub fn skipped(&self) -> impl Iterator<Item = M> + '_ {
        self.entries
            .iter()
            .filter(|(_, v)| v.is_none())
            .map(|(m, _)| *m)
    }
}

impl<M: Measure> std::ops::Index<M> for Report<M> {
    type Output = f64;

    /// The value of `measure`.
    ///
    /// # Panics
    /// If it was not computed (see [`Report::get`]).
    fn index(&self, measure: M) -> &f64 {
        self.entries
            .iter()
            .find_map(|(m, v)| (*m == measure).then_some(v.as_ref()).flatten())
            .unwrap_or_else(|| panic!("{} was not computed", measure.key()))
    }
}

impl<M: Measure> Serialize for Report<M> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut map = serializer.serialize_map(Some(1 + self.entries.len()))?;
        map.serialize_entry("n", &self.n)?;
        for (m, v) in &self.entries {
            // skipped measures are NaN: JSON writes null, Python nan
            map.serialize_entry(m.key(), &v.unwrap_or(f64::NAN))?;
        }
        map.end()
    }
}

/// Work done across threads, told to a [`Progress`] about every thousandth
/// of the total.
pub(crate) struct Tally<'a> {
    stage: &'a str,
    total: u64,
    step: u64,
    done: AtomicU64,
    progress: Progress<'a>,
}

impl<'a> Tally<'a> {
    pub(crate) fn new(stage: &'a str, total: u64, progress: Progress<'a>) -> Self {
        progress(stage, 0, total);
        Tally {
            stage,
            total,
            step: (total / 1000).max(1),
            done: AtomicU64::new(0),
            progress,
        }
    }

    pub(crate) fn add(&self, work: u64) {
        let before = self.done.fetch_add(work, Ordering::Relaxed);
        let after = before + work;
        if after / self.step != before / self.step || after == self.total {
            (self.progress)(self.stage, after, self.total);
        }
    }
}
