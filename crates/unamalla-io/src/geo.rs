//! Geographic input: longitude/latitude detection and the local projection the mesher works in.
//!
//! GeoJSON coordinates are WGS84 longitude/latitude in degrees (RFC 7946, §4). Meshing them as
//! if degrees were lengths distorts every cell (a degree of longitude at latitude φ is
//! `cos φ` times a degree of latitude), so geographic input is projected first.
//!
//! # The projection
//!
//! A **transverse Mercator** projection on the WGS84 ellipsoid, scale factor `k₀ = 1` on a
//! central meridian `λ₀` through the centre of the region's bounding box, latitude of origin
//! `φ₀` at the same centre, no false easting/northing, **output in kilometres** — the proj
//! string `+proj=tmerc +lat_0=φ₀ +lon_0=λ₀ +k=1 +x_0=0 +y_0=0 +ellps=WGS84 +units=km`
//! evaluated by the pure-Rust port of PROJ, `proj4rs` (Krüger series, Poder/Engsager, as in
//! PROJ's `tmerc`; Karney 2011, "Transverse Mercator with an accuracy of a few nanometers",
//! J. Geodesy 85). Transverse Mercator is **conformal**: angles — hence cell shapes, the
//! quantity the mesher optimises — are preserved exactly, and the scale error at a distance
//! `x` from the central meridian is `k − 1 ≈ x²/(2R²)` (R ≈ 6371 km): 0.03 % at 150 km,
//! 0.3 % at 500 km. For regions more than about 1000 km wide in longitude a lengths error of
//! a few percent is the price; pass another CRS with `--crs` then.
//!
//! Back-projection ([`LocalProjection::inverse`]) maps mesh nodes to longitude/latitude.
//!
//! # Detection
//!
//! [`looks_geographic`]: every coordinate within `−180 ≤ x ≤ 180`, `−90 ≤ y ≤ 90`. A GeoJSON
//! document that declares planar units (`"units"` in the region feature's `properties`, as the
//! bundled fixtures do, or a pre-RFC `"crs"` member that is not CRS84/EPSG:4326) is taken as
//! planar. [`CrsChoice::Auto`] then projects GeoJSON that looks geographic and leaves the rest
//! alone; for formats without a CRS convention (Shapefile without `.prj`, `.con`, text) the
//! caller should warn when [`looks_geographic`] holds and no choice was made.

use std::str::FromStr;

use proj4rs::proj::Proj;
use unamalla_mesh::{DVec2, Region};

use crate::error::IoError;

/// How the input's coordinates are to be read.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum CrsChoice {
    /// Decide from the file (see the module docs).
    #[default]
    Auto,
    /// WGS84 longitude/latitude in degrees: projected to the local transverse Mercator (km).
    LonLat,
    /// Planar coordinates, meshed as given.
    Planar,
    /// Coordinates in this PROJ.4-style CRS (e.g. `+proj=utm +zone=33 +datum=WGS84 +units=m`):
    /// converted to longitude/latitude, then to the local transverse Mercator (km).
    Proj(String),
}

impl FromStr for CrsChoice {
    type Err = IoError;

    /// `auto`, `lonlat` (also `wgs84`, `EPSG:4326`, `CRS84`), `planar` (also `none`), or a
    /// proj string starting with `+proj=`.
    fn from_str(s: &str) -> Result<Self, IoError> {
        let t = s.trim();
        match t.to_ascii_lowercase().as_str() {
            "auto" => Ok(Self::Auto),
            "lonlat" | "latlon" | "wgs84" | "epsg:4326" | "crs84" | "ogc:crs84" => Ok(Self::LonLat),
            "planar" | "none" => Ok(Self::Planar),
            _ if t.starts_with("+proj=") => {
                Proj::from_proj_string(t).map_err(|e| IoError::Crs(format!("{t:?}: {e}")))?;
                Ok(Self::Proj(t.to_string()))
            }
            _ => Err(IoError::Crs(format!(
                "unknown CRS {t:?}: use auto, lonlat, planar or a proj string such as \
                 \"+proj=utm +zone=33 +datum=WGS84 +units=m\""
            ))),
        }
    }
}

/// Whether every coordinate of `region` lies in the longitude/latitude range
/// (`|x| ≤ 180`, `|y| ≤ 90`).
pub fn looks_geographic(region: &Region) -> bool {
    let (lo, hi) = region.bounding_box();
    lo.x >= -180.0 && hi.x <= 180.0 && lo.y >= -90.0 && hi.y <= 90.0
}

/// A local transverse Mercator projection (see the module docs), optionally preceded by a
/// source CRS that is not longitude/latitude.
pub struct LocalProjection {
    lon0: f64,
    lat0: f64,
    tm: Proj,
    ll: Proj,
    source: Option<Proj>,
    source_text: Option<String>,
}

impl std::fmt::Debug for LocalProjection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LocalProjection")
            .field("proj", &self.proj_string())
            .field("source", &self.source_text)
            .finish()
    }
}

const LONLAT: &str = "+proj=longlat +ellps=WGS84 +datum=WGS84 +no_defs";

fn crs_err(e: impl std::fmt::Display) -> IoError {
    IoError::Crs(e.to_string())
}

impl LocalProjection {
    /// The projection centred on longitude `lon0`, latitude `lat0` (degrees).
    pub fn centred(lon0: f64, lat0: f64) -> Result<Self, IoError> {
        if !(lon0.abs() <= 180.0 && lat0.abs() < 90.0) {
            return Err(IoError::Crs(format!(
                "centre ({lon0}, {lat0}) is not a longitude/latitude"
            )));
        }
        let tm = Proj::from_proj_string(&tm_string(lon0, lat0)).map_err(crs_err)?;
        let ll = Proj::from_proj_string(LONLAT).map_err(crs_err)?;
        Ok(Self {
            lon0,
            lat0,
            tm,
            ll,
            source: None,
            source_text: None,
        })
    }

    /// The projection centred on the bounding box of `region`, whose coordinates are
    /// longitude/latitude in degrees.
    pub fn for_lonlat_region(region: &Region) -> Result<Self, IoError> {
        let (lo, hi) = region.bounding_box();
        let c = 0.5 * (lo + hi);
        Self::centred(c.x, c.y)
    }

    /// For a region in the CRS `source` (a proj string): centred on the region's bounding-box
    /// centre converted to longitude/latitude; [`Self::forward`] then takes `source`
    /// coordinates.
    pub fn for_source_crs(source: &str, region: &Region) -> Result<Self, IoError> {
        let src =
            Proj::from_proj_string(source).map_err(|e| crs_err(format!("{source:?}: {e}")))?;
        let ll = Proj::from_proj_string(LONLAT).map_err(crs_err)?;
        let (lo, hi) = region.bounding_box();
        let c = 0.5 * (lo + hi);
        let cll = transform(&src, &ll, c, src.is_latlong(), true)?;
        let mut p = Self::centred(cll.x, cll.y)?;
        p.source = Some(src);
        p.source_text = Some(source.to_string());
        Ok(p)
    }

    /// The central meridian and latitude of origin, degrees.
    pub fn centre(&self) -> (f64, f64) {
        (self.lon0, self.lat0)
    }

    /// The proj string of the local projection (output CRS of [`Self::forward`]).
    pub fn proj_string(&self) -> String {
        tm_string(self.lon0, self.lat0)
    }

    /// Input coordinates (longitude/latitude in degrees, or the source CRS's) → kilometres.
    pub fn forward(&self, p: DVec2) -> Result<DVec2, IoError> {
        match &self.source {
            None => transform(&self.ll, &self.tm, p, true, false),
            Some(src) => transform(src, &self.tm, p, src.is_latlong(), false),
        }
    }

    /// Kilometres → longitude/latitude in degrees (always WGS84 lon/lat, also with a source
    /// CRS).
    pub fn inverse(&self, p: DVec2) -> Result<DVec2, IoError> {
        transform(&self.tm, &self.ll, p, false, true)
    }

    /// Every ring of `region` projected by [`Self::forward`] and validated again (transverse
    /// Mercator is orientation-preserving, so rings keep their roles).
    pub fn project_region(&self, region: &Region) -> Result<Region, IoError> {
        let ring = |pts: &[DVec2]| -> Result<Vec<DVec2>, IoError> {
            pts.iter().map(|&p| self.forward(p)).collect()
        };
        let outer = ring(region.outer().points())?;
        let holes = region
            .holes()
            .iter()
            .map(|h| ring(h.points()))
            .collect::<Result<Vec<_>, _>>()?;
        Region::new(outer, holes).map_err(|e| IoError::Crs(format!("projected region: {e}")))
    }
}

fn tm_string(lon0: f64, lat0: f64) -> String {
    format!("+proj=tmerc +lat_0={lat0:?} +lon_0={lon0:?} +k=1 +x_0=0 +y_0=0 +ellps=WGS84 +units=km +no_defs")
}

/// proj4rs works in radians for geographic CRSs.
fn transform(
    from: &Proj,
    to: &Proj,
    p: DVec2,
    in_deg: bool,
    out_deg: bool,
) -> Result<DVec2, IoError> {
    let mut pt = if in_deg {
        (p.x.to_radians(), p.y.to_radians(), 0.0)
    } else {
        (p.x, p.y, 0.0)
    };
    proj4rs::transform::transform(from, to, &mut pt)
        .map_err(|e| IoError::Crs(format!("cannot transform ({}, {}): {e}", p.x, p.y)))?;
    let q = if out_deg {
        DVec2::new(pt.0.to_degrees(), pt.1.to_degrees())
    } else {
        DVec2::new(pt.0, pt.1)
    };
    if q.is_finite() {
        Ok(q)
    } else {
        Err(IoError::Crs(format!(
            "({}, {}) has no finite image in the projection",
            p.x, p.y
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_degree_of_latitude_on_the_central_meridian_is_the_meridian_arc() {
        // on the central meridian y is the meridian arc from φ₀ (k₀ = 1):
        // ∫ M(φ) dφ, M = a(1 − e²)/(1 − e² sin²φ)^{3/2}, a = 6378.137 km, f = 1/298.257223563,
        // integrated here by Simpson's rule (≈ 111.1415 km from 45° to 46°)
        let p = LocalProjection::centred(10.0, 45.0).unwrap();
        let a = p.forward(DVec2::new(10.0, 45.0)).unwrap();
        let b = p.forward(DVec2::new(10.0, 46.0)).unwrap();
        let (ax, f) = (6378.137, 1.0 / 298.257223563);
        let e2 = f * (2.0 - f);
        let m = |deg: f64| {
            let s = deg.to_radians().sin();
            ax * (1.0 - e2) / (1.0 - e2 * s * s).powf(1.5)
        };
        let n = 100;
        let h = 1.0 / n as f64;
        let mut arc = m(45.0) + m(46.0);
        for k in 1..n {
            arc += if k % 2 == 1 { 4.0 } else { 2.0 } * m(45.0 + k as f64 * h);
        }
        arc *= h.to_radians() / 3.0;
        assert!(a.length() < 1e-9, "{a}");
        assert!(b.x.abs() < 1e-9);
        assert!((b.y - arc).abs() < 1e-6, "{} vs {arc}", b.y);
    }

    #[test]
    fn a_degree_of_longitude_shrinks_with_cos_latitude() {
        // parallel arc at φ: N(φ)·cos φ·Δλ, N = a/√(1−e² sin²φ); at 60°: 55.800 km per degree.
        // On the TM plane the chord to 0.01° east is that times 0.01 (scale 1 + O(x²/R²)).
        let p = LocalProjection::centred(0.0, 60.0).unwrap();
        let b = p.forward(DVec2::new(0.01, 60.0)).unwrap();
        let a = 6378.137;
        let e2 = 0.006_694_379_990_14;
        let phi = 60f64.to_radians();
        let n = a / (1.0 - e2 * phi.sin().powi(2)).sqrt();
        let expect = n * phi.cos() * 0.01f64.to_radians();
        assert!(
            (b.length() - expect).abs() < 1e-6 * expect,
            "{} vs {expect}",
            b.length()
        );
    }

    #[test]
    fn inverse_undoes_forward() {
        let p = LocalProjection::centred(-76.5, 38.2).unwrap();
        for q in [
            DVec2::new(-77.6, 36.8),
            DVec2::new(-75.6, 39.6),
            DVec2::new(-76.5, 38.2),
        ] {
            let back = p.inverse(p.forward(q).unwrap()).unwrap();
            assert!((back - q).length() < 1e-9, "{q} -> {back}");
        }
    }

    #[test]
    fn a_source_crs_goes_through_lonlat() {
        // UTM zone 33N: the central meridian 15° E at the equator is (500 000 m, 0 m)
        let r = Region::new(
            vec![
                DVec2::new(499_000.0, 0.0),
                DVec2::new(501_000.0, 0.0),
                DVec2::new(501_000.0, 2_000.0),
                DVec2::new(499_000.0, 2_000.0),
            ],
            vec![],
        )
        .unwrap();
        let p = LocalProjection::for_source_crs("+proj=utm +zone=33 +datum=WGS84 +units=m", &r)
            .unwrap();
        let (lon0, lat0) = p.centre();
        assert!((lon0 - 15.0).abs() < 1e-9 && lat0 > 0.0 && lat0 < 0.01);
        let q = p.project_region(&r).unwrap();
        // a 2 km square stays a 2 km square (UTM scale 0.9996 vs TM k = 1)
        assert!(
            (q.area() - 4.0 / 0.9996f64.powi(2)).abs() < 1e-4,
            "{}",
            q.area()
        );
    }

    #[test]
    fn crs_choices_parse() {
        assert_eq!("auto".parse::<CrsChoice>().unwrap(), CrsChoice::Auto);
        assert_eq!("EPSG:4326".parse::<CrsChoice>().unwrap(), CrsChoice::LonLat);
        assert_eq!("planar".parse::<CrsChoice>().unwrap(), CrsChoice::Planar);
        assert!(matches!(
            "+proj=utm +zone=33 +datum=WGS84"
                .parse::<CrsChoice>()
                .unwrap(),
            CrsChoice::Proj(_)
        ));
        let e = "EPSG:32633".parse::<CrsChoice>().unwrap_err().to_string();
        assert!(e.contains("unknown CRS"), "{e}");
    }
}
