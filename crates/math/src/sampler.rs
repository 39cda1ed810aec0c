//! Samplers: where a pixel sample's uniforms come from.
//!
//! [`Sampler`] is the one interface the path loop draws through. [`Rng`] is the independent
//! sampler; [`SobolSampler`] is the low-discrepancy one: a *padded*, Owen-scrambled 2-D Sobol
//! sequence (Burley 2020, "Practical Hash-based Owen Scrambling", JCGT 9(4), §4-5; the
//! sampler pbrt-v4 calls `PaddedSobolSampler`, §8.7.5). Its value for (pixel, sample index,
//! dimension) is a pure function, so images stay bit-identical for any thread count and any
//! split of samples over passes.
//!
//! Why padded 2-D rather than one high-dimensional Sobol point: every pair of dimensions (the
//! pixel jitter, the light sample at bounce 3, the BSDF direction at bounce 1, ...) gets the
//! best 2-D stratification there is (a (0,2)-sequence), and pairs are decorrelated from each
//! other by their own random shuffle of the sample index, with no generator matrices to
//! run out of.

use crate::{Rng, mix64};

/// A source of uniforms in [0, 1) for one pixel sample (or one photon path).
pub trait Sampler {
    fn uniform(&mut self) -> f32;
    fn uniform2(&mut self) -> [f32; 2];
}

impl Sampler for Rng {
    #[inline]
    fn uniform(&mut self) -> f32 {
        Rng::uniform(self)
    }
    #[inline]
    fn uniform2(&mut self) -> [f32; 2] {
        Rng::uniform2(self)
    }
}

/// Sample `index` of the Owen-scrambled, index-shuffled 2-D Sobol sequence of one pixel.
/// Dimension `d` (counting one per call of `uniform` or `uniform2`) has its own scramble
/// seeds, derived from the pixel's seed and `d` by a hash.
#[derive(Clone, Debug)]
pub struct SobolSampler {
    seed: u64,
    /// The sample index, bit-reversed once (every dimension's shuffle starts from it).
    rindex: u32,
    dim: u32,
}

impl SobolSampler {
    /// Sample `index` of the sequence identified by `seed` (the caller mixes the run's seed
    /// and the pixel into it).
    pub fn new(seed: u64, index: u32) -> SobolSampler {
        SobolSampler {
            seed,
            rindex: index.reverse_bits(),
            dim: 0,
        }
    }

    /// 64 bits of hash for dimension `d`: SplitMix64 of the sequence's seed stepped by `d`
    /// (Steele et al. 2014), one mix per dimension.
    #[inline]
    fn hash(&mut self) -> u64 {
        let d = self.dim as u64;
        self.dim += 1;
        mix64(
            self.seed
                .wrapping_add(d.wrapping_mul(0x9e37_79b9_7f4a_7c15)),
        )
    }

    /// The sample index as dimension `h` sees it, *bit-reversed* (which is also its first
    /// Sobol coordinate, [`sobol0`]). Shuffling the index by a nested uniform scramble
    /// permutes the points of every power-of-two block among themselves (up to a digital
    /// shift), so any 2^m samples stay a (0,m,2)-net while different dimensions see the
    /// points in unrelated orders (Burley 2020, §4). `nested_uniform_scramble(index, s)`
    /// reversed is `laine_karras(reversed index, s)`: no reversal needed here.
    #[inline]
    fn shuffled_reversed(&self, h: u64) -> u32 {
        laine_karras(
            self.rindex,
            (h.wrapping_mul(0xd6e8_feb8_6659_fd93) >> 32) as u32,
        )
    }
}

impl Sampler for SobolSampler {
    #[inline]
    fn uniform(&mut self) -> f32 {
        let h = self.hash();
        let x0 = self.shuffled_reversed(h);
        // nested_uniform_scramble(x0, s) with x0 = sobol0(i) = reverse(i).
        to_unit(laine_karras(x0.reverse_bits(), h as u32).reverse_bits())
    }
    #[inline]
    fn uniform2(&mut self) -> [f32; 2] {
        let h = self.hash();
        let x0 = self.shuffled_reversed(h);
        let i = x0.reverse_bits();
        [
            to_unit(laine_karras(i, h as u32).reverse_bits()),
            to_unit(nested_uniform_scramble(sobol1(i), (h >> 32) as u32)),
        ]
    }
}

/// The top 24 bits as a float in [0, 1) (never rounds up to 1).
#[inline]
fn to_unit(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// First Sobol dimension: the van der Corput radical inverse in base 2.
#[inline]
pub fn sobol0(i: u32) -> u32 {
    i.reverse_bits()
}

/// Second Sobol dimension: generator matrix from the primitive polynomial x + 1, whose
/// direction numbers satisfy v_k = v_{k-1} xor (v_{k-1} >> 1) (Joe and Kuo 2008, dimension 2).
/// Together with [`sobol0`] it makes a (0,2)-sequence in base 2.
/// The matrix is linear over GF(2), so the product is the xor of one table entry per byte of
/// the index: four lookups instead of a loop over 32 bits.
#[inline]
pub fn sobol1(i: u32) -> u32 {
    let t = &SOBOL1_BYTES;
    t[0][(i & 0xff) as usize]
        ^ t[1][((i >> 8) & 0xff) as usize]
        ^ t[2][((i >> 16) & 0xff) as usize]
        ^ t[3][(i >> 24) as usize]
}

/// `SOBOL1_BYTES[b][x]`: xor of the direction numbers of the set bits of `x << 8b`.
static SOBOL1_BYTES: [[u32; 256]; 4] = sobol1_tables();

const fn sobol1_tables() -> [[u32; 256]; 4] {
    let mut dirs = [0u32; 32];
    let mut v = 1u32 << 31;
    let mut k = 0;
    while k < 32 {
        dirs[k] = v;
        v ^= v >> 1;
        k += 1;
    }
    let mut t = [[0u32; 256]; 4];
    let mut b = 0;
    while b < 4 {
        let mut x = 0;
        while x < 256 {
            let mut acc = 0;
            let mut bit = 0;
            while bit < 8 {
                if x & (1 << bit) != 0 {
                    acc ^= dirs[8 * b + bit];
                }
                bit += 1;
            }
            t[b][x] = acc;
            x += 1;
        }
        b += 1;
    }
    t
}

/// A hash that permutes bits only downwards (each output bit depends on itself and lower
/// bits): Laine and Karras 2011's construction with Burley 2020's constants (his Listing 4).
#[inline]
fn laine_karras(mut x: u32, seed: u32) -> u32 {
    x = x.wrapping_add(seed);
    x ^= x.wrapping_mul(0x6c50_b47c);
    x ^= x.wrapping_mul(0xb82f_1e52);
    x ^= x.wrapping_mul(0xc7af_e638);
    x ^= x.wrapping_mul(0x8d22_f6e6);
    x
}

/// Owen scrambling in base 2 as a hash: reversed, each bit flipped by a function of the bits
/// above it in the original order (Burley 2020, Listing 3).
#[inline]
pub fn nested_uniform_scramble(x: u32, seed: u32) -> u32 {
    laine_karras(x.reverse_bits(), seed).reverse_bits()
}
