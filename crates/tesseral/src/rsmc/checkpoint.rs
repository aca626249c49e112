//! Validation of a [`Checkpoint`] read from a file: every field is checked before the
//! chain trusts it, and an error names the field.

use rand_pcg::Pcg64Mcg;
use serde::Deserialize;

use super::chain::{Checkpoint, CHECKPOINT_FORMAT};
use super::{topology, RsmcError};

/// The largest coordinate a checkpoint's voxel may have: a chain grows one voxel per
/// accepted step, so a reachable surface is nowhere near the edge of `i64`, where a
/// step would wrap.
pub const MAX_CHECKPOINT_COORDINATE: i64 = 1 << 62;

/// The generator's serialized form, to read its state without access to its fields.
#[derive(Deserialize)]
struct RngState {
    state: u128,
}

fn bad(field: &str, why: impl std::fmt::Display) -> RsmcError {
    RsmcError::BadCheckpoint(format!("{field}: {why}"))
}

/// The generator's state, read through its serialized form.
fn rng_state(rng: &Pcg64Mcg) -> Option<u128> {
    let text = serde_json::to_string(rng).ok()?;
    serde_json::from_str::<RngState>(&text)
        .ok()
        .map(|s| s.state)
}

impl Checkpoint {
    /// Checks every field: the layout version, the parameters, the generator state
    /// (a multiplicative generator's state is odd; an even one, zero above all, is a
    /// degenerate stream that makes the bounded draw loop forever), the counters
    /// against each other (every attempted step is accepted, illegal, capped or
    /// refused), and the voxels (sorted, distinct, within
    /// [`MAX_CHECKPOINT_COORDINATE`], bounded by one sphere).
    ///
    /// # Runtime
    /// O(n log n) in the voxels (the topology check).
    ///
    /// # Errors
    /// [`RsmcError::BadCheckpoint`] naming the first bad field.
    ///
    /// ```
    /// use tesseral::rsmc::{Chain, DenseLattice, Lattice, Params};
    /// let mut chain = Chain::new(DenseLattice::empty(), Params::default(), 7, &[[0, 0, 0]]).unwrap();
    /// chain.run(100);
    /// let mut cp = chain.checkpoint();
    /// assert!(cp.validate().is_ok());
    /// cp.counters.accepted = cp.counters.steps + 1;
    /// assert!(cp.validate().unwrap_err().to_string().contains("counters"));
    /// ```
    pub fn validate(&self) -> Result<(), RsmcError> {
        if self.format != CHECKPOINT_FORMAT {
            return Err(bad(
                "format",
                format!("{} (this program reads {CHECKPOINT_FORMAT})", self.format),
            ));
        }
        self.params
            .validate()
            .map_err(|e| bad("params", e.to_string()))?;
        match rng_state(&self.rng) {
            Some(s) if s & 1 == 1 => {}
            Some(s) => {
                return Err(bad(
                    "rng.state",
                    format!("{s} is even; the generator's state is always odd"),
                ))
            }
            None => return Err(bad("rng.state", "unreadable")),
        }
        let k = &self.counters;
        if k.grown > k.accepted {
            return Err(bad(
                "counters.grown",
                format!("{} exceeds counters.accepted {}", k.grown, k.accepted),
            ));
        }
        let outcomes = [k.accepted, k.illegal, k.capped, k.refused]
            .iter()
            .try_fold(0u64, |a, &b| a.checked_add(b));
        if outcomes != Some(k.steps) {
            return Err(bad(
                "counters",
                format!(
                    "accepted {} + illegal {} + capped {} + refused {} is not steps {}",
                    k.accepted, k.illegal, k.capped, k.refused, k.steps
                ),
            ));
        }
        if let Some(v) = self.voxels.iter().find(|v| {
            v.iter()
                .any(|c| c.unsigned_abs() > MAX_CHECKPOINT_COORDINATE as u64)
        }) {
            return Err(bad(
                "voxels",
                format!("{v:?} lies beyond ±{MAX_CHECKPOINT_COORDINATE}"),
            ));
        }
        if !self.voxels.windows(2).all(|w| w[0] < w[1]) {
            return Err(bad("voxels", "not sorted and distinct"));
        }
        topology::check_sphere(&self.voxels).map_err(|e| bad("voxels", e))?;
        Ok(())
    }
}
