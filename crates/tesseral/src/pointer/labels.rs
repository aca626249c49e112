//! Label arithmetic of Ahuja & Nash §3.1: Table 2 and the path addition.

/// Table 2 of Ahuja & Nash: the label a node takes after a unit displacement along
/// `axis` (0 = x, 1 = y, 2 = z), and whether a carry moves its parent too.
/// Table 1's increment is `(new − old) mod 8`.
///
/// ```
/// use tesseral::pointer::label_transition;
/// assert_eq!(label_transition(7, 1), (true, 5)); // the paper's "15"
/// assert_eq!(label_transition(0, 2), (false, 4));
/// ```
#[must_use]
pub fn label_transition(label: u8, axis: usize) -> (bool, u8) {
    let bit = 1u8 << axis;
    (label & bit != 0, label ^ bit)
}

/// Adds `t` (two's complement when negative) along `axis` to a path of labels, most
/// significant (the root's child) first, digit by digit with the Table 2 carries;
/// the carry out of the top digit is dropped (§3.1).
///
/// ```
/// use tesseral::pointer::add_along_axis;
/// // §3.1: r057 moved by 1 and by 5 along +y, and r275 by -5 along y.
/// assert_eq!(add_along_axis(&[0, 5, 7], 1, 1), vec![0, 7, 5]);
/// assert_eq!(add_along_axis(&[0, 5, 7], 1, 5), vec![2, 7, 5]);
/// assert_eq!(add_along_axis(&[2, 7, 5], 1, -5), vec![0, 5, 7]);
/// ```
#[must_use]
pub fn add_along_axis(path: &[u8], axis: usize, t: i64) -> Vec<u8> {
    let mut out = path.to_vec();
    let mut carry = false;
    for (i, label) in out.iter_mut().rev().enumerate() {
        // Digit i (from the bottom) receives bit i of t and the carry from below:
        // each is one unit transition of Table 2, and at most one of them carries.
        let bit = i < 64 && (t >> i.min(63)) & 1 == 1;
        let mut next_carry = false;
        for step in [bit, carry] {
            if step {
                let (c, l) = label_transition(*label, axis);
                *label = l;
                next_carry |= c;
            }
        }
        carry = next_carry;
    }
    out
}
