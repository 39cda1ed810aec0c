//! Words and numbers of OBJ lines, read as tobj reads them (std's `split_whitespace`, `f32` and
//! `isize` parsing), with fast paths for the plain cases that give the same values.

use super::{MISSING, V_BIG, V_MISSING};

/// Whitespace-separated words, as `str::split_whitespace` gives them, bytes compared
/// directly for ASCII.
pub(super) struct Words<'a> {
    pub(super) rest: &'a str,
}

impl<'a> Words<'a> {
    fn span(&self, from: usize, ws: bool) -> usize {
        let b = self.rest.as_bytes();
        let mut i = from;
        while let Some(&c) = b.get(i) {
            let (is_ws, len) = if c < 0x80 {
                (c == b' ' || (0x09..=0x0d).contains(&c), 1)
            } else {
                match self.rest.get(i..).and_then(|s| s.chars().next()) {
                    Some(ch) => (ch.is_whitespace(), ch.len_utf8()),
                    None => (false, 1),
                }
            };
            if is_ws != ws {
                break;
            }
            i += len;
        }
        i
    }
}

impl<'a> Iterator for Words<'a> {
    type Item = &'a str;
    fn next(&mut self) -> Option<&'a str> {
        let start = self.span(0, true);
        let end = self.span(start, false);
        let word = self.rest.get(start..end)?;
        self.rest = self.rest.get(end..).unwrap_or("");
        (!word.is_empty()).then_some(word)
    }
}

/// tobj's `parse_floatn`: `n` floats from the next `n` words.
pub(super) fn floats(w: &mut Words, out: &mut Vec<f32>, n: usize) -> bool {
    for _ in 0..n {
        match w.next().map(str::parse::<f32>) {
            Some(Ok(x)) => out.push(x),
            _ => return false,
        }
    }
    true
}

/// An index word as `isize::from_str` reads it: plain digits quickly, anything else by std.
pub(super) fn int(s: &str) -> Option<i64> {
    let b = s.as_bytes();
    if !b.is_empty() && b.len() <= 18 && b.iter().all(u8::is_ascii_digit) {
        return Some(b.iter().fold(0i64, |a, &d| a * 10 + (d - b'0') as i64));
    }
    s.parse::<isize>().ok().map(|x| x as i64)
}

/// A word of decimal digits with at most one `.` and an optional sign, as `f32::from_str`
/// reads it, or `None` for anything else (an exponent, `inf`, more digits than below), which
/// the general path reads. Clinger's fast path: a significand below 2^24 and a power of ten
/// up to 10^10 are both exact in f32, so their quotient is the correctly rounded value, as
/// std's (correctly rounding) parser gives it.
pub(crate) fn decimal(w: &[u8]) -> Option<f32> {
    let (neg, digits) = match w {
        [b'-', rest @ ..] => (true, rest),
        [b'+', rest @ ..] => (false, rest),
        _ => (false, w),
    };
    if digits.is_empty() || digits.len() > 12 {
        return None;
    }
    let (mut m, mut scale, mut dot, mut any) = (0u64, 0usize, false, false);
    for &c in digits {
        match c {
            b'0'..=b'9' => {
                m = m * 10 + (c - b'0') as u64;
                scale += dot as usize;
                any = true;
            }
            b'.' if !dot => dot = true,
            _ => return None,
        }
    }
    const TEN: [f32; 11] = [1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10];
    let &p = TEN.get(scale)?;
    if !any || m > 1 << 24 {
        return None;
    }
    let x = m as f32 / p;
    Some(if neg { -x } else { x })
}

/// A position index of 1 to 9 digits (no sign, not 0), as [`Chunk::corner`] resolves it.
pub(super) fn index(w: &[u8]) -> Option<u32> {
    if w.is_empty() || w.len() > 9 || !w.iter().all(u8::is_ascii_digit) {
        return None;
    }
    let x = w.iter().fold(0u32, |a, &d| a * 10 + (d - b'0') as u32);
    x.checked_sub(1)
}

/// A resolved index as tobj's `usize` (`(count + x) as usize` for negative `x`).
pub(super) fn as_index(x: i64) -> u64 {
    x as u64
}

pub(super) fn v32(x: u64) -> u32 {
    if x == MISSING {
        V_MISSING
    } else {
        u32::try_from(x).map_or(V_BIG, |v| v.min(V_BIG))
    }
}
