//! PCG32 (O'Neill 2014, "PCG: a family of simple fast space-efficient statistically good
//! algorithms for random number generation", the XSH-RR 64/32 member), seeded by a 64-bit
//! mix of `(seed, index)` so that streams for neighbouring indices are decorrelated.

const PCG_MULT: u64 = 0x5851_f42d_4c95_7f2d;

/// SplitMix64 finaliser (Steele, Lea, Flood 2014): a bijective 64-bit mixer used to derive
/// independent PCG states and stream selectors from small integers.
#[inline]
pub fn mix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A small, fast, reproducible generator. Never shared between threads: each unit of work
/// (photon, pixel sample, test) makes its own with [`Rng::for_index`].
#[derive(Clone, Debug)]
pub struct Rng {
    state: u64,
    inc: u64,
}

impl Rng {
    /// The stream for work item `index` of a run seeded with `seed`.
    pub fn for_index(seed: u64, index: u64) -> Rng {
        let a = mix64(seed ^ mix64(index));
        let b = mix64(a ^ 0x6a09_e667_f3bc_c909);
        let mut rng = Rng {
            state: 0,
            inc: (b << 1) | 1,
        };
        rng.next_u32();
        rng.state = rng.state.wrapping_add(a);
        rng.next_u32();
        rng
    }

    /// A stream from one seed (tests, single-threaded tools).
    pub fn new(seed: u64) -> Rng {
        Rng::for_index(seed, 0)
    }

    #[inline]
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old.wrapping_mul(PCG_MULT).wrapping_add(self.inc);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }

    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        ((self.next_u32() as u64) << 32) | self.next_u32() as u64
    }

    /// Uniform in [0, 1): 24 random mantissa bits, so the result is never 1.0 after rounding.
    #[inline]
    pub fn uniform(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
    }

    #[inline]
    pub fn uniform2(&mut self) -> [f32; 2] {
        [self.uniform(), self.uniform()]
    }

    /// Uniform integer in `0..n` (Lemire's multiply-shift; the tiny bias of skipping the
    /// rejection step is below 2^-32 * n and irrelevant for rendering).
    #[inline]
    pub fn below(&mut self, n: u32) -> u32 {
        ((self.next_u32() as u64 * n as u64) >> 32) as u32
    }
}
