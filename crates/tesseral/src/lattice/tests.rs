use super::*;

#[test]
fn directions_follow_their_numbering() {
    for (i, d) in Direction::ALL.into_iter().enumerate() {
        assert_eq!(d.index(), i);
        assert_eq!(Direction::from_index(i as u8), Some(d));
        assert_eq!(d.axis() as usize, i / 2);
        assert_eq!(d.is_positive(), i % 2 == 1);
        assert_eq!(Direction::along(d.axis(), d.is_positive()), d);
        assert_eq!(d.opposite().opposite(), d);
        assert_ne!(d.opposite(), d);
        let u = d.unit();
        assert_eq!(d.opposite().unit(), u.map(|c| -c));
        let v = [10, -20, 30];
        assert_eq!(d.step(v), [v[0] + u[0], v[1] + u[1], v[2] + u[2]]);
        assert_eq!(d.opposite().step(d.step(v)), v);
    }
    assert_eq!(Direction::PosX.step([i64::MAX, 0, 0]), [i64::MIN, 0, 0]);
}

#[test]
fn a_neighbourhood_bit_is_its_offset() {
    // Every one of the 27 offsets against the definition, and each face bit against
    // its direction's unit step.
    let mut seen = 0u32;
    for dz in -1..=1 {
        for dy in -1..=1 {
            for dx in -1..=1 {
                let b = Neighbourhood::bit([dx, dy, dz]);
                assert_eq!(b as i64, (dx + 1) + 3 * (dy + 1) + 9 * (dz + 1));
                seen |= 1 << b;
                let n = Neighbourhood::EMPTY.with([dx, dy, dz]);
                assert!(n.contains([dx, dy, dz]));
                assert_eq!(n.len(), 1);
                assert_eq!(n.offsets().collect::<Vec<_>>(), vec![[dx, dy, dz]]);
                let zeros = [dx, dy, dz].iter().filter(|&&c| c == 0).count();
                assert_eq!(
                    Neighbourhood::EDGES_AND_CORNERS.contains([dx, dy, dz]),
                    zeros <= 1
                );
                assert_eq!(n.has_centre(), zeros == 3);
            }
        }
    }
    assert_eq!(seen, Neighbourhood::FULL.bits());
    assert_eq!(Neighbourhood::EDGES_AND_CORNERS.len(), 20);
    for d in Direction::ALL {
        assert_eq!(Neighbourhood::face_bit(d), Neighbourhood::bit(d.unit()));
        let n = Neighbourhood::EMPTY.with(d.unit());
        assert!(n.has_face(d));
        assert_eq!(n.faces(), Directions::EMPTY.with(d));
    }
}

#[test]
fn faces_agree_with_has_face_on_random_neighbourhoods() {
    let mut s = 0x1a77_1ce5_u64;
    for _ in 0..10_000 {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        let n = Neighbourhood::from_bits(s as u32);
        assert_eq!(n.bits() >> 27, 0);
        let f = n.faces();
        for d in Direction::ALL {
            assert_eq!(f.contains(d), n.has_face(d));
            assert_eq!(f.complement().contains(d), !n.has_face(d));
        }
        assert_eq!(f.iter().count() as u32, f.len());
        assert_eq!(n.complement().complement(), n);
        assert_eq!(n.complement().len(), 27 - n.len());
        assert_eq!(n.and(n.complement()), Neighbourhood::EMPTY);
        assert_eq!(
            f.positive().len(),
            [Direction::PosX, Direction::PosY, Direction::PosZ]
                .iter()
                .filter(|&&d| n.has_face(d))
                .count() as u32
        );
    }
}
