//! The SIMD lanes' NaN behaviour, which BVH4 traversal relies on.

use crate::simd::{F4, Lanes};

#[test]
fn nan_lanes_keep_the_accumulator() {
    let acc = F4::new(1.0, 2.0, 3.0, 4.0);
    let v = F4::new(f32::NAN, 5.0, f32::NAN, 0.0);
    assert_eq!(v.max_into(acc).to_array(), [1.0, 5.0, 3.0, 4.0]);
    assert_eq!(v.min_into(acc).to_array(), [1.0, 2.0, 3.0, 0.0]);
}
