//! Octal notation: padded codes and the P-adic signed form.

use super::*;

#[test]
fn notation_roundtrips_and_errors() {
    assert_eq!(parse_octal::<u64>("", 3), Err(ParseCodeError::Empty));
    assert_eq!(
        parse_octal::<u64>("158", 3),
        Err(ParseCodeError::InvalidDigit {
            found: '8',
            position: 3
        })
    );
    assert_eq!(
        parse_octal::<u64>("9", 3),
        Err(ParseCodeError::InvalidDigit {
            found: '9',
            position: 1
        })
    );
    assert_eq!(
        parse_octal::<u64>("0123", 3),
        Err(ParseCodeError::TooManyDigits { digits: 4, max: 3 })
    );
    assert_eq!(
        parse_octal::<u64>("x", 3),
        Err(ParseCodeError::InvalidDigit {
            found: 'x',
            position: 1
        })
    );
    assert_eq!(
        parse_octal::<u128>(&"7".repeat(42), 42),
        Ok((1u128 << 126) - 1)
    );
    let s = Space::<u128>::full();
    assert_eq!(parse_padic::<u128>("...", &s), Err(ParseCodeError::Empty));
    assert_eq!(
        parse_padic::<u128>("...8", &s),
        Err(ParseCodeError::InvalidDigit {
            found: '8',
            position: 4
        })
    );
    assert_eq!(
        parse_padic::<u128>("...69", &s),
        Err(ParseCodeError::InvalidDigit {
            found: '9',
            position: 5
        })
    );
    assert!(parse_padic::<u128>(&"1".repeat(42), &s).is_err());
    assert!(parse_padic::<u128>(&"1".repeat(41), &s).is_ok());
    let mut rng = Rng(SEED ^ 3);
    for _ in 0..2000 {
        let c = (u128::from(rng.next()) << 64 | u128::from(rng.next())) & s.mask();
        let text = format_padic(c, &s);
        assert_eq!(parse_padic(&text, &s), Ok(c), "{text}");
        let d = 1 + (rng.next() % 42) as u32;
        let c = c & Space::<u128>::new(d).unwrap().mask();
        assert_eq!(parse_octal(&format_padded(c, d), d), Ok(c));
    }
    assert_eq!(format_padic(0u128, &s), "0");
}
