//! The sensor model (log-odds increments and clamps), its fixed-point form, and the
//! sensor pose.

use super::OccupancyError;

/// Log-odds of a probability, as OctoMap computes it: `ln(p / (1 − p))` in `f64`,
/// then rounded to `f32`.
#[must_use]
pub fn log_odds(p: f64) -> f32 {
    (p / (1.0 - p)).ln() as f32
}

/// Probability of a log-odds value.
#[must_use]
pub fn probability(l: f32) -> f64 {
    1.0 - 1.0 / (1.0 + f64::from(l).exp())
}

/// OctoMap's sensor model, in log-odds: what a hit and a miss add, the clamps, and
/// the threshold above which a cell is occupied.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorModel {
    hit: f32,
    miss: f32,
    clamp_min: f32,
    clamp_max: f32,
    threshold: f32,
}

impl Default for SensorModel {
    fn default() -> Self {
        Self::octomap()
    }
}

impl SensorModel {
    /// OctoMap's defaults: hit p = 0.7 (+0.85), miss p = 0.4 (−0.405), clamped to
    /// p ∈ [0.1192, 0.971] (log-odds [−2, 3.5]), occupied from p = 0.5 (log-odds 0).
    #[must_use]
    pub fn octomap() -> Self {
        Self::from_probabilities(0.7, 0.4, (0.1192, 0.971), 0.5)
            .unwrap_or_else(|_| unreachable!("OctoMap's defaults are valid"))
    }

    /// A model from probabilities, each turned into log-odds as OctoMap does.
    ///
    /// # Errors
    /// [`OccupancyError::Sensor`] unless `0 < p < 1` for each, `hit > 0.5`,
    /// `miss < 0.5`, `clamp.0 < threshold < clamp.1`, and the clamps within
    /// log-odds ±15 (p within about 3·10⁻⁷ of 0 or 1).
    pub fn from_probabilities(
        hit: f64,
        miss: f64,
        clamp: (f64, f64),
        threshold: f64,
    ) -> Result<Self, OccupancyError> {
        let bad =
            |what: &str, p: f64| OccupancyError::Sensor(format!("{what} {p} is not in (0, 1)"));
        for (what, p) in [
            ("hit probability", hit),
            ("miss probability", miss),
            ("lower clamp", clamp.0),
            ("upper clamp", clamp.1),
            ("threshold", threshold),
        ] {
            if !(p > 0.0 && p < 1.0) {
                return Err(bad(what, p));
            }
        }
        if hit <= 0.5 {
            return Err(OccupancyError::Sensor(format!(
                "hit probability {hit} must be above 0.5"
            )));
        }
        if miss >= 0.5 {
            return Err(OccupancyError::Sensor(format!(
                "miss probability {miss} must be below 0.5"
            )));
        }
        // Strictly inside: a lower clamp at the threshold would make every cell
        // missed to the clamp read occupied (a cell is occupied at or above it).
        if !(clamp.0 < threshold && threshold < clamp.1) {
            return Err(OccupancyError::Sensor(format!(
                "the threshold {threshold} must lie strictly between the clamps {} and {}",
                clamp.0, clamp.1
            )));
        }
        Self::from_log_odds(
            log_odds(hit),
            log_odds(miss),
            (log_odds(clamp.0), log_odds(clamp.1)),
            log_odds(threshold),
        )
    }

    /// A model from its log-odds (as a map's `.tess` keeps it): `hit > 0`,
    /// `miss < 0`, the threshold strictly between the clamps (also once in fixed
    /// point), every value within ±15.
    ///
    /// # Errors
    /// [`OccupancyError::Sensor`] naming the value at fault.
    pub fn from_log_odds(
        hit: f32,
        miss: f32,
        clamp: (f32, f32),
        threshold: f32,
    ) -> Result<Self, OccupancyError> {
        let bad = |m: String| Err(OccupancyError::Sensor(m));
        let m = Self {
            hit,
            miss,
            clamp_min: clamp.0,
            clamp_max: clamp.1,
            threshold,
        };
        let all = [hit, miss, clamp.0, clamp.1, threshold];
        if !all.iter().all(|l| l.is_finite() && l.abs() <= 15.0) {
            return bad(format!(
                "log-odds {all:?} must be finite and within ±15 \
                 (a probability too close to 0 or 1)"
            ));
        }
        if !(hit > 0.0 && miss < 0.0) {
            return bad(format!(
                "a hit must add log-odds (got {hit}) and a miss remove them (got {miss})"
            ));
        }
        let f = Fixed::new(&m);
        if !(clamp.0 < threshold
            && threshold < clamp.1
            && f.min < f.threshold
            && f.threshold < f.max)
        {
            return bad(format!(
                "the threshold (log-odds {threshold}) must lie strictly between the clamps \
                 (log-odds {} and {})",
                clamp.0, clamp.1
            ));
        }
        Ok(m)
    }

    /// Log-odds added by a hit.
    #[must_use]
    pub fn hit(&self) -> f32 {
        self.hit
    }
    /// Log-odds added by a miss (negative).
    #[must_use]
    pub fn miss(&self) -> f32 {
        self.miss
    }
    /// Lower clamp, in log-odds.
    #[must_use]
    pub fn clamp_min(&self) -> f32 {
        self.clamp_min
    }
    /// Upper clamp, in log-odds.
    #[must_use]
    pub fn clamp_max(&self) -> f32 {
        self.clamp_max
    }
    /// A cell is occupied when its log-odds is at least this (OctoMap's
    /// `isNodeOccupied` compares with `>=`).
    #[must_use]
    pub fn threshold(&self) -> f32 {
        self.threshold
    }
}

/// The sensor model in fixed point: log-odds × `scale`, in `i16`. The scale is a
/// power of two chosen so that the clamps use most of the `i16` range (2¹³ for
/// OctoMap's defaults: a step of 1.2·10⁻⁴).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Fixed {
    pub hit: i16,
    pub miss: i16,
    pub min: i16,
    pub max: i16,
    pub threshold: i16,
    pub scale_log2: u32,
}

/// The stored value of an unknown cell.
pub(crate) const UNKNOWN: i16 = i16::MIN;

impl Fixed {
    pub fn new(m: &SensorModel) -> Self {
        let top = m
            .clamp_min
            .abs()
            .max(m.clamp_max.abs())
            .max(m.hit.abs())
            .max(m.miss.abs());
        // The largest power of two with top × scale ≤ 16000, so that a clamped value
        // plus an increment stays inside i16.
        let mut scale_log2 = 14;
        while scale_log2 > 0 && f64::from(top) * f64::from(1u32 << scale_log2) > 16000.0 {
            scale_log2 -= 1;
        }
        let q = |x: f32| -> i16 {
            let v = (f64::from(x) * f64::from(1u32 << scale_log2)).round();
            v as i16
        };
        Self {
            hit: q(m.hit).max(1),
            miss: q(m.miss).min(-1),
            min: q(m.clamp_min),
            max: q(m.clamp_max),
            threshold: q(m.threshold),
            scale_log2,
        }
    }

    /// The log-odds of a stored value: `v / 2^scale_log2`, as a product with
    /// `2^-scale_log2` (exact, as both are powers of two over an `i16`), since a
    /// division costs a single lookup as much as a cache hit.
    #[inline]
    pub fn to_f32(self, v: i16) -> f32 {
        // 2^-s built from its exponent bits (s ≤ 14, so a normal float).
        f32::from(v) * f32::from_bits((127 - self.scale_log2) << 23)
    }

    /// The stored value nearest a log-odds value, clamped.
    pub fn quantise(self, l: f32) -> i16 {
        let v = (f64::from(l) * f64::from(1u32 << self.scale_log2)).round();
        (v as i32).clamp(i32::from(self.min), i32::from(self.max)) as i16
    }

    /// A cell's value after a hit (`UNKNOWN` counts as 0, as a new OctoMap node).
    #[inline]
    pub fn apply_hit(self, v: i16) -> i16 {
        let v = if v == UNKNOWN { 0 } else { v };
        (v + self.hit).clamp(self.min, self.max)
    }

    /// A cell's value after a miss.
    #[inline]
    pub fn apply_miss(self, v: i16) -> i16 {
        let v = if v == UNKNOWN { 0 } else { v };
        (v + self.miss).clamp(self.min, self.max)
    }
}

/// A sensor pose: a translation and roll, pitch, yaw (radians) as OctoMap's `Pose6D`:
/// the rotation is `Rz(yaw) · Ry(pitch) · Rx(roll)`, applied before the translation.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Pose {
    /// Where the sensor is, in world units.
    pub translation: [f64; 3],
    /// Rotation about x, radians.
    pub roll: f64,
    /// Rotation about y, radians.
    pub pitch: f64,
    /// Rotation about z, radians.
    pub yaw: f64,
}

impl Pose {
    /// A pose with no rotation at `o`.
    #[must_use]
    pub fn from_origin(o: [f64; 3]) -> Self {
        Self {
            translation: o,
            ..Self::default()
        }
    }

    /// The rotation matrix, rows first (OctoMap's `Quaternion(roll, pitch, yaw)`).
    #[must_use]
    pub fn matrix(&self) -> [[f64; 3]; 3] {
        crate::io::scan::rpy_matrix([self.roll, self.pitch, self.yaw])
    }

    /// A point of the sensor frame in the world.
    #[must_use]
    pub fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        crate::io::scan::moved(&self.matrix(), self.translation, p)
    }

    /// Points of the sensor frame in the world, as [`apply`](Self::apply) moves
    /// each (in parallel).
    #[must_use]
    pub fn apply_all(&self, points: &[[f64; 3]]) -> Vec<[f64; 3]> {
        use rayon::prelude::*;
        let (m, t) = (self.matrix(), self.translation);
        points
            .par_iter()
            .map(|&p| crate::io::scan::moved(&m, t, p))
            .collect()
    }
}
