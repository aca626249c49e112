//! Pearson's chi-square goodness-of-fit test, for the detailed balance check.

/// `ln Γ(x)` for `x > 0` (Lanczos, g = 7, 9 terms; relative error below 1e-13).
#[must_use]
pub fn ln_gamma(x: f64) -> f64 {
    const G: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = G[0];
    let t = x + 7.5;
    for (i, g) in G.iter().enumerate().skip(1) {
        a += g / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// The regularized upper incomplete gamma function `Q(s, x)`.
#[must_use]
pub fn gamma_q(s: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let ln_pre = s * x.ln() - x - ln_gamma(s);
    if x < s + 1.0 {
        // Series for P.
        let mut sum = 1.0 / s;
        let mut term = sum;
        let mut n = s;
        for _ in 0..10_000 {
            n += 1.0;
            term *= x / n;
            sum += term;
            if term.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        1.0 - sum * ln_pre.exp()
    } else {
        // Continued fraction for Q (modified Lentz).
        let tiny = 1e-300;
        let mut b = x + 1.0 - s;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - s);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-16 {
                break;
            }
        }
        ln_pre.exp() * h
    }
}

/// Result of [`chi_square`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChiSquare {
    /// The statistic `Σ (O − E)² / E`.
    pub statistic: f64,
    /// Degrees of freedom: bins used minus one.
    pub dof: usize,
    /// `P(χ² ≥ statistic)`.
    pub p_value: f64,
}

/// Pearson's test of counts `observed` against probabilities `expected` (same
/// length, summing to 1). Bins with expected count below 5 are pooled into their
/// neighbour, as usual.
///
/// ```
/// use tesseral::rsmc::stats::chi_square;
/// let t = chi_square(&[50, 50], &[0.5, 0.5]);
/// assert!(t.statistic == 0.0 && t.p_value > 0.99);
/// ```
#[must_use]
pub fn chi_square(observed: &[u64], expected: &[f64]) -> ChiSquare {
    let n: u64 = observed.iter().sum();
    let mut bins: Vec<(f64, f64)> = Vec::new();
    let mut acc = (0.0, 0.0);
    for (&o, &p) in observed.iter().zip(expected) {
        acc.0 += o as f64;
        acc.1 += p * n as f64;
        if acc.1 >= 5.0 {
            bins.push(acc);
            acc = (0.0, 0.0);
        }
    }
    if acc.1 > 0.0 || acc.0 > 0.0 {
        if let Some(last) = bins.last_mut() {
            last.0 += acc.0;
            last.1 += acc.1;
        } else {
            bins.push(acc);
        }
    }
    let statistic: f64 = bins
        .iter()
        .map(|&(o, e)| if e > 0.0 { (o - e).powi(2) / e } else { 0.0 })
        .sum();
    let dof = bins.len().saturating_sub(1);
    let p_value = if dof == 0 {
        1.0
    } else {
        gamma_q(dof as f64 / 2.0, statistic / 2.0)
    };
    ChiSquare {
        statistic,
        dof,
        p_value,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_values() {
        assert!((ln_gamma(5.0) - 24f64.ln()).abs() < 1e-12);
        // χ² with 1 dof at 3.841: p = 0.05; with 10 dof at 18.307: p = 0.05.
        assert!((gamma_q(0.5, 3.841_458_820_694_124 / 2.0) - 0.05).abs() < 1e-9);
        assert!((gamma_q(5.0, 18.307_038_053_275_146 / 2.0) - 0.05).abs() < 1e-9);
        // Q(1, x) = e^-x.
        assert!((gamma_q(1.0, 0.3) - (-0.3f64).exp()).abs() < 1e-12);
        assert!((gamma_q(1.0, 7.0) - (-7.0f64).exp()).abs() < 1e-15);
        let t = chi_square(&[90, 10], &[0.5, 0.5]);
        assert!(t.p_value < 1e-10);
    }
}
