//! Encoding and decoding against the bit-by-bit reference, both widths.

use super::*;

fn check_addressing<W: CodeWord>(seed: u64) {
    println!("seed {seed:#x}");
    let mut rng = Rng(seed);
    let n = 5000;
    let pts: Vec<[u64; 3]> = (0..n)
        .map(|_| random_point(&mut rng, W::MAX_DEPTH))
        .collect();
    let coords: Vec<[W::Coord; 3]> = pts.iter().map(|p| p.map(W::coord_from_u64)).collect();
    let mut out = vec![W::ZERO; n];
    let mut back = vec![[W::Coord::default(); 3]; n];
    for backend in [Backend::MagicBits, Backend::Bmi2] {
        if !backend.is_available() {
            println!("{backend:?} not available on this CPU: skipped");
            continue;
        }
        batch::encode_slice_with(backend, &coords, &mut out).unwrap();
        batch::decode_slice_with(backend, &out, &mut back).unwrap();
        for i in 0..n {
            let want: W = naive_encode(pts[i]);
            assert_eq!(
                out[i], want,
                "{backend:?} encode {:?} (seed {seed:#x})",
                pts[i]
            );
            assert_eq!(naive_decode(out[i]), pts[i]);
            assert_eq!(back[i].map(W::coord_to_u64), pts[i], "{backend:?} decode");
            let [x, y, z] = coords[i];
            assert_eq!(W::encode(x, y, z), want);
            assert_eq!(want.decode(), coords[i]);
            if backend == Backend::Bmi2 {
                // SAFETY: availability checked above.
                unsafe {
                    assert_eq!(W::encode_bmi2(x, y, z), want);
                    assert_eq!(want.decode_bmi2(), coords[i]);
                }
            }
        }
    }
}

#[test]
fn addressing_u64_matches_bit_by_bit_reference() {
    check_addressing::<u64>(SEED);
}

#[test]
fn addressing_u128_matches_bit_by_bit_reference() {
    check_addressing::<u128>(SEED ^ 0x55);
}

#[test]
fn addressing_edges() {
    let m21 = (1u32 << 21) - 1;
    assert_eq!(encode(m21, m21, m21), (1u64 << 63) - 1);
    assert_eq!(decode((1u64 << 63) - 1), [m21; 3]);
    // Bits above depth 21 are dropped, and bit 63 of a code is ignored.
    assert_eq!(encode(1 << 21, 0, 0), 0);
    assert_eq!(decode(1 << 63), [0, 0, 0]);
    let m42 = (1u64 << 42) - 1;
    assert_eq!(encode_wide(m42, m42, m42), (1u128 << 126) - 1);
    assert_eq!(decode_wide((1u128 << 126) - 1), [m42; 3]);
    assert_eq!(encode_wide(1 << 42, 0, 0), 0);
    assert_eq!(dilate3(m21), 0x1249_2492_4924_9249);
    assert_eq!(undilate3(!0), m21);
    assert_eq!(<u64 as CodeWord>::X_MASK, 0x1249_2492_4924_9249);
    assert_eq!(
        batch::encode_slice::<u64>(&[[0, 0, 0]], &mut []),
        Err(CodeError::LengthMismatch { src: 1, dst: 0 })
    );
}

proptest! {
    #[test]
    fn prop_u64_roundtrip(x in 0u32..1 << 21, y in 0u32..1 << 21, z in 0u32..1 << 21) {
        let c = encode(x, y, z);
        prop_assert_eq!(c, naive_encode::<u64>([x.into(), y.into(), z.into()]));
        prop_assert_eq!(decode(c), [x, y, z]);
        if Backend::Bmi2.is_available() {
            // SAFETY: availability checked.
            unsafe {
                prop_assert_eq!(<u64 as CodeWord>::encode_bmi2(x, y, z), c);
                prop_assert_eq!(c.decode_bmi2(), [x, y, z]);
            }
        }
    }

    #[test]
    fn prop_u128_roundtrip(x in 0u64..1 << 42, y in 0u64..1 << 42, z in 0u64..1 << 42) {
        let c = encode_wide(x, y, z);
        prop_assert_eq!(c, naive_encode::<u128>([x, y, z]));
        prop_assert_eq!(decode_wide(c), [x, y, z]);
        if Backend::Bmi2.is_available() {
            // SAFETY: availability checked.
            unsafe {
                prop_assert_eq!(<u128 as CodeWord>::encode_bmi2(x, y, z), c);
                prop_assert_eq!(c.decode_bmi2(), [x, y, z]);
            }
        }
    }
}
