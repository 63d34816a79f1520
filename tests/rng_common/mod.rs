//! One small deterministic generator for the test files that draw random cases (xorshift64*),
//! so each file does not carry its own copy.

/// xorshift64*: the next value uniform in [0, 1), advancing `state` (any nonzero seed).
pub fn next_unit(state: &mut u64) -> f64 {
    *state ^= *state >> 12;
    *state ^= *state << 25;
    *state ^= *state >> 27;
    (state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
}
