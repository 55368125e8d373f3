//! Analytic densities on the unit sphere.

use super::{Density, Uniform};
use crate::healpix::FacePoint;
use crate::tiling::sphere::{SphereRegion, FACE_LIPSCHITZ};
use crate::Error;
use glam::DVec3;
use std::f64::consts::PI;

/// Geodesic angle between two unit vectors, stable for tiny and near-pi angles.
///
/// # Example
/// ```
/// use glam::DVec3;
/// let a = tessera::density::sphere::angle_between(DVec3::X, DVec3::Y);
/// assert!((a - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
/// ```
pub fn angle_between(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

pub use crate::healpix::lonlat_to_vec;

/// Density `contrast` inside a spherical cap and 1 outside.
///
/// # Example
/// ```
/// use tessera::density::{sphere::Cap, Density};
/// use tessera::tiling::sphere::SphereRegion;
/// let cap = Cap::new(0.0, 90.0, 10.0, 100.0).unwrap();
/// assert_eq!(Density::<SphereRegion>::value(&cap, glam::DVec3::Z), 100.0);
/// assert_eq!(Density::<SphereRegion>::value(&cap, -glam::DVec3::Z), 1.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cap {
    center: DVec3,
    radius: f64,
    contrast: f64,
}

impl Cap {
    /// A cap centred at (`lon`, `lat`) degrees with angular radius
    /// `radius_deg` degrees, where the density is `contrast` (>= 0) times the
    /// density outside.
    ///
    /// # Example
    /// ```
    /// assert!(tessera::density::sphere::Cap::new(0.0, 0.0, 5.0, -1.0).is_err());
    /// ```
    pub fn new(lon: f64, lat: f64, radius_deg: f64, contrast: f64) -> Result<Self, Error> {
        let spec = || format!("cap:{lon},{lat},{radius_deg},{contrast}");
        if ![lon, lat, radius_deg, contrast]
            .iter()
            .all(|v| v.is_finite())
        {
            return Err(Error::Density(spec(), "every number must be finite".into()));
        }
        if !(-90.0..=90.0).contains(&lat) {
            return Err(Error::Density(
                spec(),
                "latitude must be in [-90, 90]".into(),
            ));
        }
        if !(0.0..=180.0).contains(&radius_deg) {
            return Err(Error::Density(
                spec(),
                "radius must be in [0, 180] degrees".into(),
            ));
        }
        if contrast < 0.0 {
            return Err(Error::Density(spec(), "contrast must be >= 0".into()));
        }
        if contrast == 0.0 && radius_deg >= 180.0 {
            return Err(Error::Density(
                spec(),
                "the density is zero everywhere".into(),
            ));
        }
        Ok(Cap {
            center: lonlat_to_vec(lon, lat),
            radius: radius_deg.to_radians(),
            contrast,
        })
    }

    /// Solid angle of the cap, computed without cancellation for tiny radii.
    ///
    /// # Example
    /// ```
    /// let cap = tessera::density::sphere::Cap::new(0.0, 0.0, 180.0, 2.0).unwrap();
    /// assert!((cap.solid_angle() - 4.0 * std::f64::consts::PI).abs() < 1e-12);
    /// ```
    pub fn solid_angle(&self) -> f64 {
        // 2 pi (1 - cos r) = 4 pi sin^2(r/2)
        4.0 * PI * (self.radius / 2.0).sin().powi(2)
    }

    /// Whether a unit vector lies inside the (closed) cap.
    ///
    /// # Example
    /// ```
    /// let cap = tessera::density::sphere::Cap::new(0.0, 0.0, 1.0, 2.0).unwrap();
    /// assert!(cap.contains(glam::DVec3::X));
    /// ```
    pub fn contains(&self, v: DVec3) -> bool {
        angle_between(self.center, v) <= self.radius
    }

    /// A window `LON,LAT,RADIUS_DEG` (degrees), as a cap of contrast 1: for
    /// [`Cap::reaches`] and [`Cap::contains`].
    ///
    /// # Example
    /// ```
    /// use tessera::density::sphere::Cap;
    /// assert!(Cap::window("0,90,1").unwrap().contains(glam::DVec3::Z));
    /// assert!(Cap::window("0,90").is_err());
    /// ```
    pub fn window(spec: &str) -> Result<Self, Error> {
        let window = || -> Result<Self, Error> {
            let [lon, lat, radius] = numbers(spec, spec, "LON,LAT,RADIUS_DEG")?;
            Cap::new(lon, lat, radius, 1.0)
        };
        window().map_err(|e| match e {
            Error::Density(_, why) => Error::Request(format!("window '{spec}': {why}")),
            other => other,
        })
    }

    /// Whether a tile may reach into the cap (conservative: true when the
    /// tile's bounding cap meets this one). A window for
    /// [`crate::engine::collect_within`].
    ///
    /// # Example
    /// ```
    /// use tessera::{density::sphere::Cap, tiling::{sphere::SphereTiling, TileSystem}};
    /// let sphere = SphereTiling::default();
    /// let cap = Cap::new(0.0, 90.0, 1.0, 1.0).unwrap();
    /// let reached = sphere.roots().iter().filter(|t| cap.reaches(&sphere.region(t))).count();
    /// assert!(reached >= 4 && reached < 20);
    /// ```
    pub fn reaches(&self, region: &SphereRegion) -> bool {
        angle_between(self.center, region.center()) - region.radius <= self.radius
    }

    /// The fraction of a sample set's expected mass that lies in the cap.
    ///
    /// # Example
    /// ```
    /// let cap = tessera::density::sphere::Cap::new(0.0, 90.0, 90.0, 3.0).unwrap();
    /// assert!((cap.mass_fraction() - 0.75).abs() < 1e-12);
    /// ```
    pub fn mass_fraction(&self) -> f64 {
        let inside = self.contrast * self.solid_angle();
        inside / (inside + 4.0 * PI - self.solid_angle())
    }

    /// The bound over the cap of `radius` at angle `distance` from the
    /// cap's centre.
    fn bound_at(&self, distance: f64, radius: f64) -> f64 {
        if distance + radius <= self.radius {
            self.contrast
        } else if distance - radius > self.radius {
            1.0
        } else {
            self.contrast.max(1.0)
        }
    }
}

impl Density<SphereRegion> for Cap {
    fn bound(&self, region: &SphereRegion) -> f64 {
        self.bound_at(angle_between(self.center, region.center()), region.radius)
    }
    fn bounds(&self, region: &SphereRegion, inner: &SphereRegion) -> (f64, f64) {
        if region.centroid != inner.centroid {
            return (self.bound(region), self.bound(inner));
        }
        // one centre, two radii
        let distance = angle_between(self.center, region.center());
        (
            self.bound_at(distance, region.radius),
            self.bound_at(distance, inner.radius),
        )
    }
    fn average(&self, region: &SphereRegion) -> f64 {
        let distance = angle_between(self.center, region.center());
        if distance + region.radius <= self.radius {
            return self.contrast;
        }
        if distance - region.radius > self.radius {
            return 1.0;
        }
        let probes = region.probes();
        probes.iter().map(|&p| self.value(p)).sum::<f64>() / probes.len() as f64
    }
    fn value(&self, point: DVec3) -> f64 {
        if self.contains(point) {
            self.contrast
        } else {
            1.0
        }
    }
    fn mean(&self) -> f64 {
        let a = self.solid_angle();
        (self.contrast * a + (4.0 * PI - a)) / (4.0 * PI)
    }
}

/// A density given by a closure of the direction, with a Lipschitz constant
/// (per radian) that makes its tile bounds conservative: the largest value
/// at the tile's five cell centres plus `lipschitz` times the distance
/// every point lies within of one ([`SphereRegion::cell_reach`]; a bare cap:
/// `f(centre) + lipschitz * radius`), and optionally a relative one
/// ([`SphereFn::with_relative_lipschitz`]).
///
/// # Example
/// ```
/// use tessera::density::{sphere::SphereFn, Density};
/// use tessera::tiling::sphere::SphereRegion;
/// // brighter towards +Z; |grad| <= 1 per radian
/// let d = SphereFn::new(|v: glam::DVec3| 1.0 + v.z, 1.0).unwrap();
/// assert!((Density::<SphereRegion>::mean(&d) - 1.0).abs() < 1e-3);
/// ```
pub struct SphereFn<F> {
    f: F,
    lipschitz: f64,
    /// A bound on `|grad f| / f` (per radian), if given.
    relative_lipschitz: Option<f64>,
    mean: f64,
}

impl<F: Fn(DVec3) -> f64 + Sync> SphereFn<F> {
    /// Wraps `f` (negative and non-finite values count as 0). The mean is
    /// estimated by the equal-area quadrature of HEALPix cell centres at
    /// Nside 64; use [`SphereFn::with_mean`] when it is known exactly.
    ///
    /// # Example
    /// ```
    /// use tessera::density::sphere::SphereFn;
    /// assert!(SphereFn::new(|_| 0.0, 0.0).is_err());
    /// ```
    pub fn new(f: F, lipschitz: f64) -> Result<Self, Error> {
        if !(lipschitz.is_finite() && lipschitz >= 0.0) {
            return Err(Error::Density(
                "closure".into(),
                format!("Lipschitz constant {lipschitz} must be finite and >= 0"),
            ));
        }
        let mean = cell_centre_mean(64, |v| clean(f(v)));
        if mean.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) || !mean.is_finite() {
            return Err(Error::Density(
                "closure".into(),
                format!("its mean over the sphere is {mean}; it must be positive and finite"),
            ));
        }
        Ok(SphereFn {
            f,
            lipschitz,
            relative_lipschitz: None,
            mean,
        })
    }

    /// Replaces the estimated mean (integral / 4 pi) by an exact value.
    ///
    /// # Example
    /// ```
    /// use tessera::density::{sphere::SphereFn, Density};
    /// use tessera::tiling::sphere::SphereRegion;
    /// let d = SphereFn::new(|v: glam::DVec3| 1.0 + v.z, 1.0).unwrap().with_mean(1.0);
    /// assert_eq!(Density::<SphereRegion>::mean(&d), 1.0);
    /// ```
    pub fn with_mean(mut self, mean: f64) -> Self {
        self.mean = mean;
        self
    }

    /// Adds `k`, a bound on `|grad f| / f` (per radian; `|grad ln f|`
    /// where `f > 0`): a tile's bound becomes the smaller of
    /// `f + lipschitz * d` and `f * exp(k * d)`, `f` the largest value at
    /// the tile's cell centres and `d` the distance every point lies within
    /// of one (see [`SphereFn`]; where a cell centre has `f = 0`, the first
    /// alone). Where a density spans a wide range, its Lipschitz constant
    /// is set by the steep bright part, and over the dim parts it
    /// overstates the density many times; the engine then places samples
    /// for the bound and thins them to the density, which costs their
    /// spacing (docs/SPHERE_ADAPTIVE.md, the bump). A von Mises-Fisher
    /// lobe `exp(kappa (v . mu - 1))` has `k = kappa`.
    ///
    /// Errors: `k` negative or not finite.
    ///
    /// # Example
    /// ```
    /// use tessera::density::{sphere::SphereFn, Density};
    /// use tessera::tiling::{sphere::SphereTiling, TileSystem};
    /// let kappa = 20.0;
    /// let lobe = |v: glam::DVec3| (kappa * (v.z - 1.0)).exp();
    /// let plain = SphereFn::new(lobe, kappa).unwrap();
    /// let relative = SphereFn::new(lobe, kappa).unwrap().with_relative_lipschitz(kappa).unwrap();
    /// // a root tile on the equator, where the lobe is about e^-20
    /// let sphere = SphereTiling::default();
    /// let tile = sphere.roots().into_iter()
    ///     .map(|root| sphere.region(&root))
    ///     .find(|region| region.center().z.abs() < 0.1)
    ///     .unwrap();
    /// assert!(relative.bound(&tile) < 1e-4 && plain.bound(&tile) > 1.0);
    /// assert!(SphereFn::new(lobe, kappa).unwrap().with_relative_lipschitz(-1.0).is_err());
    /// ```
    pub fn with_relative_lipschitz(mut self, k: f64) -> Result<Self, Error> {
        if !(k.is_finite() && k >= 0.0) {
            return Err(Error::Density(
                "closure".into(),
                format!("relative Lipschitz constant {k} must be finite and >= 0"),
            ));
        }
        self.relative_lipschitz = Some(k);
        Ok(self)
    }
}

/// Negative and non-finite importance counts as zero.
fn clean(v: f64) -> f64 {
    if v.is_finite() && v > 0.0 {
        v
    } else {
        0.0
    }
}

impl<F: Fn(DVec3) -> f64 + Sync> SphereFn<F> {
    /// The largest and least value at a region's five cell centres.
    fn probed(&self, region: &SphereRegion) -> (f64, f64) {
        let values = region.probes().map(|p| clean((self.f)(p)));
        let most = values.iter().copied().fold(0.0, f64::max);
        (most, values.iter().copied().fold(f64::INFINITY, f64::min))
    }

    /// The bound `distance` from points whose largest and least values are
    /// `(value, least)`.
    fn grown(&self, (value, least): (f64, f64), distance: f64) -> f64 {
        let additive = value + self.lipschitz * distance;
        match self.relative_lipschitz {
            // f <= f(p) e^(k d) at distance d from p, where no probe is 0
            Some(k) if least > 0.0 => additive.min(value * (k * distance).exp()),
            _ => additive,
        }
    }
}

impl<F: Fn(DVec3) -> f64 + Sync> Density<SphereRegion> for SphereFn<F> {
    fn bound(&self, region: &SphereRegion) -> f64 {
        // every sample the bound covers lies within `cell_reach` of one of
        // the tile's five cell centres; where that is less than the cap's
        // radius (past level 2), the bound grows less from their largest
        // value than from the centre's (a bare cap is known only by its
        // centre)
        let reach = region.cell_reach();
        if reach < region.radius {
            self.grown(self.probed(region), reach)
        } else {
            let centre = clean((self.f)(region.center()));
            self.grown((centre, centre), region.radius)
        }
    }

    fn bounds(&self, region: &SphereRegion, inner: &SphereRegion) -> (f64, f64) {
        let (reach, inner_reach) = (region.cell_reach(), inner.cell_reach());
        let same_probes = region.face == inner.face && region.cells == inner.cells;
        if reach >= region.radius || inner_reach >= inner.radius || !same_probes {
            return (self.bound(region), self.bound(inner));
        }
        // the same five probes
        let probed = self.probed(region);
        (self.grown(probed, reach), self.grown(probed, inner_reach))
    }
    fn average(&self, region: &SphereRegion) -> f64 {
        let probes = region.probes();
        probes.iter().map(|&p| clean((self.f)(p))).sum::<f64>() / probes.len() as f64
    }
    fn value(&self, point: DVec3) -> f64 {
        clean((self.f)(point))
    }
    fn mean(&self) -> f64 {
        self.mean
    }
}

/// Parses a command-line density: `uniform` or `cap:LON,LAT,RADIUS_DEG,CONTRAST`.
///
/// # Example
/// ```
/// use tessera::density::sphere::parse;
/// assert!(parse("uniform").is_ok());
/// assert!(parse("cap:10,20,5,100").is_ok());
/// let err = parse("cap:1,2").err().unwrap().to_string();
/// assert!(err.contains("cap:1,2"));
/// ```
pub fn parse(spec: &str) -> Result<Box<dyn Density<SphereRegion> + Send>, Error> {
    let fail = |why: &str| Error::Density(spec.to_string(), why.to_string());
    if spec == "uniform" {
        return Ok(Box::new(Uniform));
    }
    if let Some(args) = spec.strip_prefix("cap:") {
        let [lon, lat, radius, contrast] = cap_numbers(spec, args)?;
        return Cap::new(lon, lat, radius, contrast)
            .map(|c| Box::new(c) as Box<dyn Density<SphereRegion> + Send>)
            .map_err(|e| match e {
                Error::Density(_, why) => fail(&why),
                other => other,
            });
    }
    Err(fail(
        "unknown density; expected 'uniform', 'cap:LON,LAT,RADIUS_DEG,CONTRAST' or 'polygon:LON LAT,LON LAT,...;CONTRAST'",
    ))
}

/// The four numbers `LON,LAT,RADIUS_DEG,CONTRAST` of a `cap:` specification
/// (`args` is what follows the prefix), shared by every parser of caps.
pub(crate) fn cap_numbers(spec: &str, args: &str) -> Result<[f64; 4], Error> {
    numbers(spec, args, "cap:LON,LAT,RADIUS_DEG,CONTRAST")
}

/// `N` comma-separated numbers, or an error naming `spec` and the `usage`.
fn numbers<const N: usize>(spec: &str, args: &str, usage: &str) -> Result<[f64; N], Error> {
    let fail = |why: String| Error::Density(spec.to_string(), why);
    let numbers: Vec<f64> = args
        .split(',')
        .map(|s| s.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| fail(format!("expected numbers: {usage}")))?;
    numbers[..]
        .try_into()
        .map_err(|_| fail(format!("expected {N} numbers: {usage}")))
}

/// The mean of `f` over the sphere by the equal-area quadrature of the
/// HEALPix cell centres at `nside` (`12 nside^2` evaluations).
pub(crate) fn cell_centre_mean(nside: u32, f: impl Fn(DVec3) -> f64) -> f64 {
    let side = nside as f64;
    let mut sum = 0.0;
    for face in 0..12u8 {
        for j in 0..nside {
            for i in 0..nside {
                let (x, y) = ((i as f64 + 0.5) / side, (j as f64 + 0.5) / side);
                sum += f(FacePoint::new(face, x, y).to_vec());
            }
        }
    }
    sum / (12.0 * side * side)
}

/// A sphere density sampled in a uniformly random rotated frame: the
/// engine samples `value(p) = inner(rotation p)`, and
/// [`Rotated::to_world`] maps its samples back. Averaged over seeds,
/// estimates from the samples are unbiased (see [`crate::engine`]).
///
/// It bounds the inner density over each tile's bounding cap (centre and
/// radius), which is all that [`Cap`], [`SphereFn`] and
/// [`super::region::Regions`] read of a tile; an environment map rotates
/// itself ([`super::envmap::EnvMap::with_seed`]).
///
/// # Example
/// ```
/// use tessera::density::{sphere::{Cap, Rotated}, Density};
/// use tessera::{engine, tiling::sphere::SphereTiling};
/// let cap = Rotated::new(Cap::new(0.0, 90.0, 20.0, 50.0).unwrap(), 7);
/// let s = engine::generate(&SphereTiling::default(), &cap, 500, true).unwrap();
/// let north = s.iter().filter(|s| cap.to_world(s.position).z > 0.94).count();
/// assert!(north > 300);
/// ```
pub struct Rotated<D> {
    inner: D,
    rotation: glam::DMat3,
    seed: u64,
}

impl<D> Rotated<D> {
    /// `inner` in the frame of [`crate::random::random_rotation`]`(seed)`.
    ///
    /// # Example
    /// ```
    /// use tessera::density::{sphere::Rotated, Uniform};
    /// let r = Rotated::new(Uniform, 3);
    /// assert!((r.to_world(glam::DVec3::Z).length() - 1.0).abs() < 1e-12);
    /// ```
    pub fn new(inner: D, seed: u64) -> Self {
        Rotated {
            inner,
            rotation: crate::random::random_rotation(seed),
            seed,
        }
    }

    /// The world direction of a sample of the rotated frame.
    ///
    /// # Example
    /// ```
    /// use tessera::density::{sphere::Rotated, Uniform};
    /// let r = Rotated::new(Uniform, 3);
    /// assert_ne!(r.to_world(glam::DVec3::Z), glam::DVec3::Z);
    /// ```
    pub fn to_world(&self, p: DVec3) -> DVec3 {
        self.rotation * p
    }

    /// The tile's bounding cap, rotated into the world.
    fn cap_of(&self, region: &SphereRegion) -> SphereRegion {
        let centre = crate::healpix::FacePoint::from_vec(self.rotation * region.center());
        SphereRegion {
            centroid: centre,
            radius: region.radius,
            face: centre.face,
            cells: [[centre.x, centre.y]; 5],
            spill: 0.0,
            warp: 0.0,
            stretch: FACE_LIPSCHITZ,
        }
    }
}

impl<D: Density<SphereRegion>> Density<SphereRegion> for Rotated<D> {
    fn bound(&self, region: &SphereRegion) -> f64 {
        self.inner.bound(&self.cap_of(region))
    }
    fn bounds(&self, region: &SphereRegion, inner: &SphereRegion) -> (f64, f64) {
        if region.centroid != inner.centroid {
            return (self.bound(region), self.bound(inner));
        }
        // one centre to turn
        let cap = self.cap_of(region);
        let inner_cap = SphereRegion {
            radius: inner.radius,
            ..cap
        };
        self.inner.bounds(&cap, &inner_cap)
    }
    fn average(&self, region: &SphereRegion) -> f64 {
        let probes = region.probes();
        probes.iter().map(|&p| self.value(p)).sum::<f64>() / probes.len() as f64
    }
    fn value(&self, point: DVec3) -> f64 {
        self.inner.value(self.rotation * point)
    }
    fn mean(&self) -> f64 {
        self.inner.mean()
    }
    fn constant(&self) -> Option<f64> {
        self.inner.constant()
    }
    fn seed(&self) -> Option<u64> {
        Some(self.seed)
    }
}
