//! The Markov chain (Libes §6, one Monte Carlo step), with the Hastings correction.

use rand::{RngCore, SeedableRng};
use rand_pcg::Pcg64Mcg;
use serde::{Deserialize, Serialize};

use super::legality::legal_join;
use super::{topology, Direction, Lattice, RsmcError};
use crate::Voxel;

/// Version of the [`Checkpoint`] layout.
pub const CHECKPOINT_FORMAT: u32 = 1;

/// The model's parameters: the weight `exp(−β·A − μ·V)` of a surface of area `A`
/// (plaquettes) enclosing `V` voxels, an optional area cap, and the acceptance rule.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Params {
    /// Cost of one plaquette, β.
    pub beta: f64,
    /// Cost of one enclosed voxel, μ (0 for the pure area model).
    pub mu: f64,
    /// Moves that would make the area larger than this are rejected.
    pub max_area: Option<u64>,
    /// Include the Hastings factor for the proposal probabilities (detailed balance
    /// with respect to the weight). `false` is Libes's original rule: accept every
    /// legal move with the Metropolis factor alone (with β = μ = 0: every legal move).
    pub hastings: bool,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            beta: 0.0,
            mu: 0.0,
            max_area: None,
            hastings: true,
        }
    }
}

impl Params {
    /// Checks the ranges: β and μ finite, `max_area` at least 6.
    ///
    /// # Errors
    /// [`RsmcError::InvalidParameter`] naming the bad parameter.
    pub fn validate(&self) -> Result<(), RsmcError> {
        if !self.beta.is_finite() {
            return Err(RsmcError::InvalidParameter(format!(
                "beta = {} is not finite",
                self.beta
            )));
        }
        if !self.mu.is_finite() {
            return Err(RsmcError::InvalidParameter(format!(
                "mu = {} is not finite",
                self.mu
            )));
        }
        if let Some(m) = self.max_area {
            if m < 6 {
                return Err(RsmcError::InvalidParameter(format!(
                    "max_area = {m} is below 6, the area of one voxel"
                )));
            }
        }
        Ok(())
    }
}

/// What happened to the attempted steps so far.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Counters {
    /// Attempted steps.
    pub steps: u64,
    /// Accepted moves.
    pub accepted: u64,
    /// Accepted growth moves.
    pub grown: u64,
    /// Proposals rejected by the topology rules.
    pub illegal: u64,
    /// Proposals rejected by the area cap.
    pub capped: u64,
    /// Legal proposals rejected by the Metropolis–Hastings test.
    pub refused: u64,
}

/// One row of a chain's trajectory: its state after `step` attempted steps, as the
/// CLI's `series.csv` and Python's `rsmc` report it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Attempted steps so far.
    pub step: u64,
    /// Area A (plaquettes).
    pub area: u64,
    /// Volume V (voxels).
    pub volume: u64,
    /// Radius of gyration of the voxel centres.
    pub radius_of_gyration: f64,
    /// Accepted over attempted steps since the counters `since` (0 when none).
    pub acceptance: f64,
}

/// Everything needed to continue a chain exactly: parameters, counters, the random
/// generator's state and the voxels. The lattice is rebuilt from the voxels in
/// sorted order, which fixes the face-list order (see [`Chain::canonicalize`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Checkpoint {
    /// Layout version, [`CHECKPOINT_FORMAT`].
    pub format: u32,
    /// The model.
    pub params: Params,
    /// The seed the chain started from.
    pub seed: u64,
    /// Counters at the checkpoint.
    pub counters: Counters,
    /// The generator, mid-stream.
    pub rng: Pcg64Mcg,
    /// The black voxels, sorted.
    pub voxels: Vec<Voxel>,
}

/// A random-surface Markov chain on lattice `L`.
///
/// One step ([`Chain::step`], Libes §6): draw a face uniformly (probability 1/A) and
/// grow or shrink with probability ½ each; reject if illegal
/// ([`super::legality`]) or past the area cap; otherwise accept with probability
/// `min(1, w(T)·q(T→S) / (w(S)·q(S→T)))`, where `w = exp(−βA − μV)`. A move that
/// toggles voxel `p` is proposed by `k` faces (the faces of `p`'s face neighbours of
/// the colour `p` joins), so `q(S→T) = k/(2A)` and `q(T→S) = (6−k)/(2A')`.
///
/// The stationary distribution on surfaces up to translation is then
/// `∝ exp(−βA − μV)`, restricted to `A ≤ max_area`.
pub struct Chain<L: Lattice> {
    lattice: L,
    params: Params,
    seed: u64,
    rng: Pcg64Mcg,
    counters: Counters,
    sum: [i128; 3],
    sum_sq: i128,
    max_area: usize,
    /// `weight[shrink as usize][k]`: the acceptance ratio without the A/A' factor.
    weight: [[f64; 7]; 2],
}

impl<L: Lattice> Chain<L> {
    /// A chain on `lattice` (which must be empty) starting from the voxels `start`,
    /// with the generator seeded from `seed`. O(|start|) plus a global topology check.
    ///
    /// # Errors
    /// Bad parameters, or a start shape that is not bounded by one sphere.
    pub fn new(lattice: L, params: Params, seed: u64, start: &[Voxel]) -> Result<Self, RsmcError> {
        params.validate()?;
        let mut voxels = start.to_vec();
        voxels.sort_unstable();
        voxels.dedup();
        topology::check_sphere(&voxels)?;
        Self::build(
            lattice,
            params,
            seed,
            Pcg64Mcg::seed_from_u64(seed),
            Counters::default(),
            &voxels,
        )
    }

    /// Continues the chain saved in `cp` on `lattice` (which must be empty).
    ///
    /// # Errors
    /// [`RsmcError::BadCheckpoint`] naming the field, for any field that
    /// [`Checkpoint::validate`] rejects, or a surface larger than its area cap.
    pub fn from_checkpoint(lattice: L, cp: Checkpoint) -> Result<Self, RsmcError> {
        cp.validate()?;
        let chain = Self::build(lattice, cp.params, cp.seed, cp.rng, cp.counters, &cp.voxels)?;
        if let Some(m) = cp.params.max_area {
            if chain.area() > m {
                return Err(RsmcError::BadCheckpoint(format!(
                    "params.max_area: the surface's area {} exceeds it ({m})",
                    chain.area()
                )));
            }
        }
        Ok(chain)
    }

    fn build(
        mut lattice: L,
        params: Params,
        seed: u64,
        rng: Pcg64Mcg,
        counters: Counters,
        sorted: &[Voxel],
    ) -> Result<Self, RsmcError> {
        if lattice.voxel_count() != 0 {
            return Err(RsmcError::InvalidParameter(
                "the lattice must start empty".into(),
            ));
        }
        let mut sum = [0i128; 3];
        let mut sum_sq = 0i128;
        for &v in sorted {
            lattice.insert(v);
            for a in 0..3 {
                sum[a] += i128::from(v[a]);
                sum_sq += i128::from(v[a]) * i128::from(v[a]);
            }
        }
        let mut weight = [[0.0; 7]; 2];
        for (shrink, row) in weight.iter_mut().enumerate() {
            let dv = if shrink == 1 { -1.0 } else { 1.0 };
            for (k, w) in row.iter_mut().enumerate().take(6).skip(1) {
                let da = 6.0 - 2.0 * k as f64;
                let mut r = (-params.beta * da - params.mu * dv).exp();
                if params.hastings {
                    r *= (6 - k) as f64 / k as f64;
                }
                *w = r;
            }
        }
        let max_area = params
            .max_area
            .map_or(usize::MAX, |m| usize::try_from(m).unwrap_or(usize::MAX));
        Ok(Chain {
            lattice,
            params,
            seed,
            rng,
            counters,
            sum,
            sum_sq,
            max_area,
            weight,
        })
    }

    /// A uniform integer below `n` (Lemire's method, exact). `n > 0`.
    #[inline]
    fn below(&mut self, n: u64) -> u64 {
        let mut m = u128::from(self.rng.next_u64()) * u128::from(n);
        if (m as u64) < n {
            let t = n.wrapping_neg() % n;
            while (m as u64) < t {
                m = u128::from(self.rng.next_u64()) * u128::from(n);
            }
        }
        (m >> 64) as u64
    }

    /// One attempted Monte Carlo step; true when the move was accepted. O(1) plus the
    /// lattice's operations.
    #[inline]
    pub fn step(&mut self) -> bool {
        self.counters.steps += 1;
        let area = self.lattice.face_count();
        let r = self.below(2 * area as u64);
        let face = self.lattice.face((r >> 1) as usize);
        let shrink = r & 1 == 1;
        let p = if shrink { face.voxel } else { face.outside() };
        let nb = self.lattice.neighbourhood(p);
        let joins = if shrink { nb.complement() } else { nb };
        if !legal_join(joins) {
            self.counters.illegal += 1;
            return false;
        }
        let k = joins.faces().len() as usize;
        let new_area = area + 6 - 2 * k;
        if new_area > self.max_area {
            self.counters.capped += 1;
            return false;
        }
        let mut ratio = self.weight[shrink as usize][k];
        if self.params.hastings {
            ratio *= area as f64 / new_area as f64;
        }
        if ratio < 1.0 {
            let u = (self.rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64);
            if u >= ratio {
                self.counters.refused += 1;
                return false;
            }
        }
        let sign: i128 = if shrink { -1 } else { 1 };
        for (sum, &x) in self.sum.iter_mut().zip(&p) {
            *sum += sign * i128::from(x);
            self.sum_sq += sign * i128::from(x) * i128::from(x);
        }
        if shrink {
            self.lattice.remove_with_neighbourhood(p, nb);
        } else {
            self.lattice.insert_with_neighbourhood(p, nb);
            self.counters.grown += 1;
        }
        self.counters.accepted += 1;
        true
    }

    /// Runs `n` attempted steps. O(n).
    pub fn run(&mut self, n: u64) {
        for _ in 0..n {
            self.step();
        }
    }

    /// Attempted steps so far.
    #[must_use]
    pub fn steps(&self) -> u64 {
        self.counters.steps
    }

    /// The counters.
    #[must_use]
    pub fn counters(&self) -> Counters {
        self.counters
    }

    /// The parameters.
    #[must_use]
    pub fn params(&self) -> Params {
        self.params
    }

    /// The seed the chain started from.
    #[must_use]
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// The chain's state now, with the acceptance rate since the counters `since`
    /// (taken at the previous sample; `Counters::default()` for the start).
    #[must_use]
    pub fn sample(&self, since: Counters) -> Sample {
        let k = self.counters;
        let steps = k.steps.saturating_sub(since.steps);
        let accepted = k.accepted.saturating_sub(since.accepted);
        Sample {
            step: k.steps,
            area: self.area(),
            volume: self.volume(),
            radius_of_gyration: self.radius_of_gyration(),
            acceptance: if steps == 0 {
                0.0
            } else {
                accepted as f64 / steps as f64
            },
        }
    }

    /// The area A (plaquettes). O(1).
    #[must_use]
    pub fn area(&self) -> u64 {
        self.lattice.face_count() as u64
    }

    /// The volume V (voxels). O(1).
    #[must_use]
    pub fn volume(&self) -> u64 {
        self.lattice.voxel_count()
    }

    /// Radius of gyration of the voxel centres. O(1).
    #[must_use]
    pub fn radius_of_gyration(&self) -> f64 {
        let v = self.volume() as f64;
        let mean_sq = self.sum_sq as f64 / v;
        let c: f64 = self.sum.iter().map(|&s| (s as f64 / v).powi(2)).sum();
        (mean_sq - c).max(0.0).sqrt()
    }

    /// The lattice.
    #[must_use]
    pub fn lattice(&self) -> &L {
        &self.lattice
    }

    /// The black voxels, sorted: a flood fill from the surface voxels through
    /// `contains`, so it needs nothing beyond the [`Lattice`] trait. O(V log V).
    #[must_use]
    pub fn voxels(&self) -> Vec<Voxel> {
        let mut seen = std::collections::HashSet::new();
        let mut stack = Vec::new();
        for i in 0..self.lattice.face_count() {
            let v = self.lattice.face(i).voxel;
            if seen.insert(v) {
                stack.push(v);
            }
        }
        while let Some(v) = stack.pop() {
            for d in Direction::ALL {
                let n = d.step(v);
                if self.lattice.contains(n) && seen.insert(n) {
                    stack.push(n);
                }
            }
        }
        let mut out: Vec<Voxel> = seen.into_iter().collect();
        out.sort_unstable();
        out
    }

    /// The surface's faces, in face-list order.
    #[must_use]
    pub fn faces(&self) -> Vec<super::Face> {
        (0..self.lattice.face_count())
            .map(|i| self.lattice.face(i))
            .collect()
    }

    /// Rebuilds the lattice by inserting the voxels in sorted order. The face list,
    /// and so every later step, then depends on the voxel set alone, not on the
    /// history: this is what makes a resumed run equal an uninterrupted one. The CLI
    /// calls it at every checkpoint, in the live run as well. O(V log V).
    pub fn canonicalize(&mut self) {
        let voxels = self.voxels();
        let mut fresh = L::empty();
        for &v in &voxels {
            fresh.insert(v);
        }
        self.lattice = fresh;
    }

    /// Checks the chain's bookkeeping against its lattice: the counters add up, the
    /// coordinate sums match the voxels, the voxel count and area match, and the
    /// surface passes the global sphere check. O(V log V).
    ///
    /// # Panics
    /// When something does not hold.
    pub fn assert_valid(&self) {
        let k = self.counters;
        assert_eq!(
            k.steps,
            k.accepted + k.illegal + k.capped + k.refused,
            "counters {k:?}"
        );
        assert!(k.grown <= k.accepted, "counters {k:?}");
        let voxels = self.voxels();
        assert_eq!(
            voxels.len() as u64,
            self.lattice.voxel_count(),
            "voxel count"
        );
        let mut sum = [0i128; 3];
        let mut sum_sq = 0i128;
        for v in &voxels {
            for a in 0..3 {
                sum[a] += i128::from(v[a]);
                sum_sq += i128::from(v[a]) * i128::from(v[a]);
            }
        }
        assert_eq!((sum, sum_sq), (self.sum, self.sum_sq), "coordinate sums");
        let report = topology::check_sphere(&voxels).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(report.faces, self.area(), "area");
    }

    /// Canonicalizes (see [`Chain::canonicalize`]) and returns the state.
    #[must_use]
    pub fn checkpoint(&mut self) -> Checkpoint {
        self.canonicalize();
        Checkpoint {
            format: CHECKPOINT_FORMAT,
            params: self.params,
            seed: self.seed,
            counters: self.counters,
            rng: self.rng.clone(),
            voxels: self.voxels(),
        }
    }
}
