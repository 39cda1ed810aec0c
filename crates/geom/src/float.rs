//! Floating-point error helpers (pbrt-v4 §6.8.1–6.8.2): ulp steps and the `gamma(n)` bound on
//! `n` successive roundings.

/// Machine epsilon in pbrt's sense: half an ulp of 1.0 (the maximum relative rounding error).
pub const MACHINE_EPSILON: f32 = f32::EPSILON * 0.5;

/// `gamma(n) = n eps / (1 - n eps)`: bounds the relative error of `n` chained f32 operations.
#[inline]
pub fn gamma(n: i32) -> f32 {
    let ne = n as f32 * MACHINE_EPSILON;
    ne / (1.0 - ne)
}

/// The next representable f32 above `v` (+0 and -0 both step to the smallest positive).
#[inline]
pub fn next_up(v: f32) -> f32 {
    if v.is_infinite() && v > 0.0 {
        return v;
    }
    let v = if v == -0.0 { 0.0 } else { v };
    let bits = v.to_bits();
    let bits = if v >= 0.0 { bits + 1 } else { bits - 1 };
    f32::from_bits(bits)
}

/// The next representable f32 below `v`.
#[inline]
pub fn next_down(v: f32) -> f32 {
    if v.is_infinite() && v < 0.0 {
        return v;
    }
    let v = if v == 0.0 { -0.0 } else { v };
    let bits = v.to_bits();
    let bits = if v > 0.0 { bits - 1 } else { bits + 1 };
    f32::from_bits(bits)
}
