//! Tesseral multiplication, division and quaternion rotation against
//! decode-compute-encode models on seeded random codes.

use std::collections::BTreeSet;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::muldiv::{padic_div, quaternion_apply, DivisionError};
use super::{Axis, Space};

fn random_code(rng: &mut Pcg64, s: &Space<u64>) -> u64 {
    rng.random::<u64>() & s.mask()
}

#[test]
fn multiplication_is_the_product_of_coordinates() {
    let mut rng = Pcg64::seed_from_u64(16);
    for _ in 0..20_000 {
        let depth = rng.random_range(0..=21);
        let s = Space::<u64>::new(depth).unwrap();
        let (a, b) = (random_code(&mut rng, &s), random_code(&mut rng, &s));
        let (ua, ub) = (s.decode_unsigned(a), s.decode_unsigned(b));
        let side = 1u128 << depth;
        let product: [u128; 3] = [0, 1, 2].map(|i| u128::from(ua[i]) * u128::from(ub[i]));
        let r = s.overflowing_mul(a, b);
        let want = s
            .encode_unsigned(product.map(|p| (p % side) as u64))
            .unwrap();
        assert_eq!(r.code, want, "depth {depth}: {a:o} * {b:o}");
        let carry = (0..3).fold(0, |c, i| c | (u8::from(product[i] >= side) << i));
        assert_eq!(r.carry, carry, "depth {depth}: {a:o} * {b:o}");
        // Signed: the product of two's-complement coordinates, when it fits.
        let (sa, sb) = (s.decode_signed(a), s.decode_signed(b));
        let p: [i128; 3] = [0, 1, 2].map(|i| i128::from(sa[i]) * i128::from(sb[i]));
        let half = if depth == 0 { 1 } else { 1i128 << (depth - 1) };
        let fits = depth == 0 || p.iter().all(|&c| (-half..half).contains(&c));
        let got = s.checked_mul_signed(a, b);
        if fits {
            let got = got.unwrap_or_else(|| panic!("depth {depth}: {sa:?} * {sb:?}"));
            if depth > 0 {
                assert_eq!(s.decode_signed(got).map(i128::from), p);
            }
        } else {
            assert_eq!(got, None, "depth {depth}: {sa:?} * {sb:?} = {p:?}");
        }
        assert_eq!(s.mul(a, b), r.code);
    }
}

#[test]
fn seven_is_the_unit_and_seventy_doubles() {
    let s = Space::<u64>::full();
    for code in [0o0, 0o1, 0o642, 0o6530, 0o7777, 0o123456] {
        assert_eq!(s.mul(code, 0o7), code);
        assert_eq!(s.mul(0o7, code), code);
        assert_eq!(s.mul(code, 0o70), code << 3);
    }
    // A single axis: 1 scales x only; a negative coordinate mirrors.
    let t = Space::<u64>::new(6).unwrap();
    let v = t.encode_signed([5, -3, 2]).unwrap();
    let m = t.encode_signed([-1, 1, 1]).unwrap();
    assert_eq!(
        t.decode_signed(t.checked_mul_signed(v, m).unwrap()),
        [-5, -3, 2]
    );
}

/// The 2-adic number with these leading digits and then `repeat` forever, to `n`
/// digits.
fn expand(leading: &[u8], repeat: &[u8], n: usize) -> u128 {
    (0..n).fold(0u128, |r, i| {
        let d = if i < leading.len() {
            leading[i]
        } else {
            repeat[(i - leading.len()) % repeat.len()]
        };
        r | (u128::from(d) << (3 * i))
    })
}

#[test]
fn division_inverts_multiplication_as_2_adic_numbers() {
    let mut rng = Pcg64::seed_from_u64(17);
    let wide = Space::<u128>::full();
    for _ in 0..5_000 {
        let depth = rng.random_range(1..=12);
        let s = Space::<u64>::new(depth).unwrap();
        let half = 1i64 << (depth - 1);
        let mut coord = || rng.random_range(-half..half);
        let (b, a) = ([0; 3].map(|_| coord()), [0; 3].map(|_| coord()));
        let (cb, ca) = (s.encode_signed(b).unwrap(), s.encode_signed(a).unwrap());
        let q = padic_div(&s, cb, ca, true, 1 << 14);
        if let Some(axis) = Axis::ALL.into_iter().find(|&ax| a[ax as usize] == 0) {
            assert_eq!(q, Err(DivisionError::ByZero(axis)));
            continue;
        }
        // The first axis whose divisor has more factors of two than the dividend.
        let v2 = |x: i64| if x == 0 { 64 } else { x.trailing_zeros() };
        let bad = Axis::ALL
            .into_iter()
            .find(|&ax| v2(a[ax as usize]) > v2(b[ax as usize]));
        let q = match (bad, q) {
            (Some(axis), r) => {
                assert_eq!(r, Err(DivisionError::NotDivisible(axis)), "{b:?} / {a:?}");
                continue;
            }
            (None, r) => r.unwrap(),
        };
        // The quotient times the odd divisor is the halved dividend, modulo the space.
        let halved_b = q.halvings.last().map_or(cb, |h| h.2);
        assert_eq!(s.mul(q.result, q.divisor), halved_b, "{b:?} / {a:?}");
        // The repeating digits hold far beyond the space: check to 42 digits.
        // Per axis the remainders come back within |divisor| + 2 steps or so.
        assert!(q.cycles.iter().all(Option::is_some), "{b:?} / {a:?}");
        let digits: Vec<u8> = (0..42).map(|i| q.digit(i).unwrap()).collect();
        let x = expand(&digits, &[0], 42);
        let sb = s.decode_signed(halved_b);
        let sa = s.decode_signed(q.divisor);
        let (wb, wa) = (
            wide.encode_wrapping(sb).to_owned(),
            wide.encode_wrapping(sa).to_owned(),
        );
        assert_eq!(wide.mul(x, wa), wb, "{b:?} / {a:?} to 42 digits");
        // An exact integer quotient comes out as that integer.
        if (0..3).all(|i| b[i] % a[i] == 0) {
            let want: [i64; 3] = std::array::from_fn(|i| b[i] / a[i]);
            if let Some(w) = s.encode_signed(want) {
                assert_eq!(q.result, w, "{b:?} / {a:?}");
                let repeat = q.repeating_digits(64).unwrap();
                assert_eq!(repeat.len(), 1, "an integer repeats its sign digit");
            }
        }
    }
}

#[test]
fn one_third_repeats_with_period_two() {
    let s = Space::<u64>::full();
    // 1/3 along x (y and z divide 0 by 1).
    let three = s.encode_signed([3, 1, 1]).unwrap();
    let q = padic_div(&s, 0o1, three, true, 64).unwrap();
    assert_eq!(s.decode_signed(q.divisor)[0], 3);
    // 1/3 = ...010101011 in binary: digits 1, 1, then (0, 1) repeating.
    assert_eq!(q.leading_digits(), vec![1]);
    assert_eq!(q.repeating_digits(64).unwrap(), vec![1, 0]);
    assert_eq!(s.mul(q.result, q.divisor), 0o1);
}

#[test]
fn even_divisors_halve_first_and_errors_name_the_axis() {
    let s = Space::<u64>::new(8).unwrap();
    let enc = |p| s.encode_signed(p).unwrap();
    let q = padic_div(&s, enc([6, 8, -4]), enc([2, 4, 2]), true, 64).unwrap();
    assert_eq!(s.decode_signed(q.result), [3, 2, -2]);
    assert!(!q.halvings.is_empty());
    assert_eq!(
        padic_div(&s, enc([6, 3, 1]), enc([2, 2, 1]), true, 64),
        Err(DivisionError::NotDivisible(Axis::Y))
    );
    assert_eq!(
        padic_div(&s, enc([6, 3, 1]), enc([2, 1, 0]), true, 64),
        Err(DivisionError::ByZero(Axis::Z))
    );
}

/// The rotation matrix of `q v q̄ / |q|²`, when it is integral.
fn scaled_back(q: [i64; 4]) -> Option<[[i64; 3]; 3]> {
    let n = q.iter().map(|c| c * c).sum::<i64>();
    let mut m = [[0i64; 3]; 3];
    for (j, e) in [[1, 0, 0], [0, 1, 0], [0, 0, 1]].into_iter().enumerate() {
        let r = quaternion_apply(q, e);
        for i in 0..3 {
            if r[i] % i128::from(n) != 0 {
                return None;
            }
            m[i][j] = (r[i] / i128::from(n)) as i64;
        }
    }
    Some(m)
}

#[test]
fn the_24_rotations_of_the_cube_come_from_unit_and_half_unit_quaternions() {
    let mut rotations = BTreeSet::new();
    for q0 in -1..=1 {
        for q1 in -1..=1 {
            for q2 in -1..=1 {
                for q3 in -1..=1 {
                    let q = [q0, q1, q2, q3];
                    let n = q.iter().map(|c| c * c).sum::<i64>();
                    // Units (norm 1), units times (1 + axis)/sqrt 2 (norm 2), and
                    // Hurwitz half units scaled by 2 (norm 4).
                    if ![1, 2, 4].contains(&n) {
                        continue;
                    }
                    let m = scaled_back(q).expect("an integral rotation");
                    // A proper rotation of the cube: a signed permutation, det 1.
                    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
                    assert_eq!(det, 1, "{q:?}");
                    assert!(m.iter().all(|r| r.iter().filter(|&&c| c != 0).count() == 1));
                    rotations.insert(m);
                }
            }
        }
    }
    assert_eq!(rotations.len(), 24);
}

#[test]
fn a_quaternion_rotates_about_its_vector_and_scales_by_its_norm() {
    let mut rng = Pcg64::seed_from_u64(18);
    for _ in 0..2_000 {
        let q: [i64; 4] = [0; 4].map(|_| rng.random_range(-9..=9));
        let n = q.iter().map(|c| c * c).sum::<i64>() as f64;
        if n == 0.0 {
            continue;
        }
        let v: [i64; 3] = [0; 3].map(|_| rng.random_range(-50..=50));
        let got = quaternion_apply(q, v).map(|c| c as f64);
        // Rodrigues: angle 2 atan2(|u|, a) about u, then scale by the norm.
        let u = [q[1], q[2], q[3]].map(|c| c as f64);
        let len = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
        let theta = 2.0 * len.atan2(q[0] as f64);
        let k = if len > 0.0 {
            u.map(|c| c / len)
        } else {
            [0.0; 3]
        };
        let vf = v.map(|c| c as f64);
        let kv = k[0] * vf[0] + k[1] * vf[1] + k[2] * vf[2];
        let kxv = [
            k[1] * vf[2] - k[2] * vf[1],
            k[2] * vf[0] - k[0] * vf[2],
            k[0] * vf[1] - k[1] * vf[0],
        ];
        for i in 0..3 {
            let want =
                n * (vf[i] * theta.cos() + kxv[i] * theta.sin() + k[i] * kv * (1.0 - theta.cos()));
            assert!((got[i] - want).abs() < 1e-6 * n * 100.0, "{q:?} {v:?}");
        }
    }
}
