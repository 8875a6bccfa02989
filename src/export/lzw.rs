//! The GIF's LZW compression, with runs of one index compressed in time proportional to the
//! codes they produce rather than to their length.
//!
//! A GIF frame after the first stores only what changed, and most of its box is the
//! "unchanged" index ([`super::palette::TRANSPARENT`]) in long runs. A plain LZW encoder walks its
//! dictionary once per input byte, so three quarters of its time went to those runs. The
//! dictionary of LZW is prefix-closed: when the string `bᵏ⁺¹` (the byte `b` repeated) has a
//! code, so has `bᵏ`. This encoder keeps, for every byte `b`, the codes of `b², b³, …` in order
//! as they are created, so a run of `r` more `b` after a current string `bᵏ` is matched in one
//! step (the longest `bʲ` with a code, `j ≤ k + r`), exactly as the byte-by-byte walk would.
//!
//! The output is greedy LZW as the `weezl` encoder the `gif` crate uses
//! ([`gif::Frame::make_lzw_pre_encoded`]) writes it: a clear code first, code width growing from
//! `min_code_size + 1` up to 12 bits, a clear code as soon as the 4096th entry would be made, the
//! end code, little-endian bit packing. It is the same bits as long as no string has more than
//! 16 continuations; `weezl` loses the 17th from its dictionary (it never matches it again), so
//! from there on its codes can differ and this encoder's are as short or shorter. The tests
//! decode every case back with the `gif` crate.

/// Largest code width of GIF's LZW, bits.
const MAX_BITS: u8 = 12;
/// Entries of a full dictionary.
const MAX_ENTRIES: usize = 1 << MAX_BITS;

/// An LZW encoder for GIF image data, reusable across frames (keep one per thread: its
/// dictionary table is 2 MB, allocated once).
pub struct Lzw {
    /// `child[code · 256 + byte]`: the code of the string `code` followed by `byte`, 0 = none
    /// (no string's code is 0 but the byte 0 itself, which is never a child).
    child: Vec<u16>,
    /// Slots of `child` set since the last clear, to undo them.
    set: Vec<u32>,
    /// `runs[b][j]`: the code of `b` repeated `j + 2` times.
    runs: Vec<Vec<u16>>,
    /// Bytes whose `runs` are not empty.
    run_bytes: Vec<u8>,
}

impl Default for Lzw {
    fn default() -> Self {
        Lzw::new()
    }
}

impl std::fmt::Debug for Lzw {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Lzw").finish_non_exhaustive()
    }
}

/// Little-endian bit packer.
struct Bits<'a> {
    out: &'a mut Vec<u8>,
    acc: u64,
    n: u32,
}

impl Bits<'_> {
    #[inline]
    fn put(&mut self, code: u16, width: u8) {
        self.acc |= (code as u64) << self.n;
        self.n += width as u32;
        while self.n >= 8 {
            self.out.push(self.acc as u8);
            self.acc >>= 8;
            self.n -= 8;
        }
    }

    fn finish(mut self) {
        if self.n > 0 {
            self.out.push(self.acc as u8);
            self.n = 0;
            self.acc = 0;
        }
    }
}

/// The dictionary's growth: next code, code width and the clear/end codes.
struct Dict {
    next: usize,
    width: u8,
    min: u8,
    clear: u16,
}

impl Lzw {
    /// An encoder with an empty dictionary.
    pub fn new() -> Lzw {
        Lzw {
            child: vec![0; MAX_ENTRIES * 256],
            set: Vec::with_capacity(MAX_ENTRIES),
            runs: vec![Vec::new(); 256],
            run_bytes: Vec::new(),
        }
    }

    /// Forgets every entry (a clear code).
    fn reset(&mut self) {
        for &s in &self.set {
            self.child[s as usize] = 0;
        }
        self.set.clear();
        for &b in &self.run_bytes {
            self.runs[b as usize].clear();
        }
        self.run_bytes.clear();
    }

    /// The GIF minimum code size for `data`, as the `gif` crate chooses it: enough bits for its
    /// largest index, at least 2.
    pub fn min_code_size(data: &[u8]) -> u8 {
        let mut max = 0u8;
        for &b in data {
            if b > max {
                max = b;
                if b > 127 {
                    break;
                }
            }
        }
        (u32::from(max) + 1)
            .max(4)
            .next_power_of_two()
            .trailing_zeros() as u8
    }

    /// Appends `[min_code_size]` and the LZW code stream of `data` to `out`: the layout
    /// [`gif::Encoder::write_lzw_pre_encoded_frame`] takes (it cuts it into sub-blocks).
    pub fn encode_frame(&mut self, data: &[u8], out: &mut Vec<u8>) {
        let min = Lzw::min_code_size(data);
        out.push(min);
        self.encode(data, min, out);
    }

    /// Appends the LZW code stream of `data` with minimum code size `min` (2..=8; every byte
    /// must be below `2^min`) to `out`.
    pub fn encode(&mut self, data: &[u8], min: u8, out: &mut Vec<u8>) {
        debug_assert!((2..=8).contains(&min));
        self.reset();
        let clear = 1u16 << min;
        let end = clear + 1;
        let mut d = Dict {
            next: clear as usize + 2,
            width: min + 1,
            min,
            clear,
        };
        let mut bits = Bits { out, acc: 0, n: 0 };
        bits.put(clear, d.width);
        let Some((&first, _)) = data.split_first() else {
            bits.put(end, d.width);
            bits.finish();
            return;
        };
        // The current string's code, and `(b, k)` when it is `b` repeated `k` times.
        let mut cur = first as u16;
        let mut run: Option<(u8, usize)> = Some((first, 1));
        let n = data.len();
        let mut i = 1;
        while i < n {
            let c = data[i];
            if let Some((b, k)) = run {
                if c == b {
                    // The run of `b` from `i`, and the longest `bʲ` the dictionary holds.
                    let r = run_length(&data[i..], b);
                    let m = self.runs[b as usize].len() + 1;
                    if k + r <= m {
                        cur = self.run_code(b, k + r);
                        run = Some((b, k + r));
                        i += r;
                        continue;
                    }
                    // Match up to `bᵐ`, then the next `b` has no entry: emit and start over.
                    let top = self.run_code(b, m);
                    i += m - k;
                    self.add_and_emit(top, b, &mut d, &mut bits);
                    cur = b as u16;
                    run = Some((b, 1));
                    i += 1;
                    continue;
                }
            }
            let slot = cur as usize * 256 + c as usize;
            let ch = self.child[slot];
            if ch != 0 {
                cur = ch;
                run = None;
            } else {
                self.add_and_emit(cur, c, &mut d, &mut bits);
                cur = c as u16;
                run = Some((c, 1));
            }
            i += 1;
        }
        bits.put(cur, d.width);
        // The decoder adds an entry on reading this code before the end code.
        if d.next >= (1usize << d.width) && d.width < MAX_BITS {
            d.width += 1;
        }
        bits.put(end, d.width);
        bits.finish();
    }

    /// The code of `b` repeated `k ≥ 1` times (which must exist).
    #[inline]
    fn run_code(&self, b: u8, k: usize) -> u16 {
        if k == 1 {
            b as u16
        } else {
            self.runs[b as usize][k - 2]
        }
    }

    /// Makes the entry `cur` + `c`, writes `cur`, widens the codes or clears the dictionary as
    /// the `weezl` encoder does.
    #[inline]
    fn add_and_emit(&mut self, cur: u16, c: u8, d: &mut Dict, bits: &mut Bits) {
        let code = d.next as u16;
        let slot = cur as usize * 256 + c as usize;
        self.child[slot] = code;
        self.set.push(slot as u32);
        // `cur` is `cᵏ` (the last of its chain): the new entry is `cᵏ⁺¹`.
        let chain = &mut self.runs[c as usize];
        let last = chain.last().copied().unwrap_or(c as u16);
        if last == cur {
            if chain.is_empty() {
                self.run_bytes.push(c);
            }
            chain.push(code);
        }
        d.next += 1;
        bits.put(cur, d.width);
        if d.next > (1usize << d.width) && d.width < MAX_BITS {
            d.width += 1;
        }
        if d.next > MAX_ENTRIES {
            bits.put(d.clear, d.width);
            self.reset();
            d.next = d.clear as usize + 2;
            d.width = d.min + 1;
        }
    }
}

/// How many bytes at the start of `data` equal `b`.
#[inline]
fn run_length(data: &[u8], b: u8) -> usize {
    let pat = u64::from_ne_bytes([b; 8]);
    let mut i = 0;
    let mut chunks = data.chunks_exact(8);
    for ch in &mut chunks {
        let v = u64::from_ne_bytes(ch.try_into().expect("8 bytes")) ^ pat;
        if v != 0 {
            let same = if cfg!(target_endian = "little") {
                v.trailing_zeros()
            } else {
                v.leading_zeros()
            } / 8;
            return i + same as usize;
        }
        i += 8;
    }
    i + chunks.remainder().iter().take_while(|&&x| x == b).count()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    fn weezl(data: &[u8]) -> Vec<u8> {
        let mut f = gif::Frame {
            width: data.len().max(1) as u16,
            height: 1,
            buffer: std::borrow::Cow::Owned(data.to_vec()),
            ..gif::Frame::default()
        };
        f.make_lzw_pre_encoded();
        f.buffer.into_owned()
    }

    fn ours(data: &[u8]) -> Vec<u8> {
        let mut out = Vec::new();
        Lzw::new().encode_frame(data, &mut out);
        out
    }

    #[test]
    fn run_length_counts_the_leading_equal_bytes() {
        let mut v = vec![7u8; 37];
        assert_eq!(run_length(&v, 7), 37);
        assert_eq!(run_length(&v, 6), 0);
        v[19] = 1;
        assert_eq!(run_length(&v, 7), 19);
        v[3] = 1;
        assert_eq!(run_length(&v, 7), 3);
        assert_eq!(run_length(&[], 7), 0);
    }

    /// `data` written as a one-row-per-`w` GIF frame with our codes, decoded by the `gif` crate.
    fn round_trip(data: &[u8], code: Vec<u8>) -> Vec<u8> {
        let w = 1000usize.min(data.len().max(1));
        let h = data.len().div_ceil(w).max(1);
        assert_eq!(w * h, data.len().max(1), "test data must fill rows");
        let mut file = Vec::new();
        {
            let mut enc = gif::Encoder::new(&mut file, w as u16, h as u16, &[0u8; 768]).unwrap();
            let f = gif::Frame {
                width: w as u16,
                height: h as u16,
                buffer: std::borrow::Cow::Owned(code),
                ..gif::Frame::default()
            };
            enc.write_lzw_pre_encoded_frame(&f).unwrap();
        }
        let mut o = gif::DecodeOptions::new();
        o.set_color_output(gif::ColorOutput::Indexed);
        let mut d = o.read_info(&file[..]).unwrap();
        d.read_next_frame().unwrap().unwrap().buffer.to_vec()
    }

    #[test]
    fn decodes_back_to_its_input_at_the_gif_crates_size_or_less() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let mut enc = Lzw::new();
        let mut cases: Vec<Vec<u8>> = vec![
            vec![3],
            vec![255; 1],
            vec![255; 2],
            vec![255; 100_000],
            vec![0; 70_000],
            (0..=255).cycle().take(1000).collect(),
            (0..60_000).map(|i| (i % 7) as u8).collect(),
        ];
        // Sparse changes in transparent runs (a GIF delta frame), of several index ranges
        // (min code sizes 2..8) and lengths that fill the dictionary many times over.
        for (len, colours, p) in [
            (50_000usize, 256u32, 0.05f64),
            (200_000, 255, 0.01),
            (120_000, 200, 0.3),
            (30_000, 4, 0.5),
            (30_000, 16, 0.2),
            (80_000, 100, 0.9),
            (5_000, 2, 0.5),
        ] {
            let t = (colours - 1) as u8;
            let mut v = Vec::with_capacity(len);
            while v.len() < len {
                if rng.random_bool(p) {
                    let c = rng.random_range(0..colours) as u8;
                    let r = rng.random_range(1..6);
                    v.extend(std::iter::repeat_n(c, r));
                } else {
                    let r = rng.random_range(1..400);
                    v.extend(std::iter::repeat_n(t, r));
                }
            }
            v.truncate(len);
            cases.push(v);
        }
        for (i, v) in cases.iter().enumerate() {
            let mut out = Vec::new();
            enc.encode_frame(v, &mut out);
            assert_eq!(
                round_trip(v, out.clone()),
                *v,
                "case {i} ({} bytes)",
                v.len()
            );
            // A fresh encoder and a reused one agree.
            assert_eq!(out, ours(v), "case {i}");
            // The gif crate's encoder drops a node's 17th continuation from its dictionary, so
            // it can only be as small or larger (by a hair).
            let theirs = weezl(v).len();
            assert!(
                out.len() <= theirs + theirs / 200 + 2,
                "case {i}: {} bytes vs {theirs}",
                out.len()
            );
        }
        // Same bits as the gif crate's encoder while no node has more than 16 continuations.
        for v in [
            vec![255u8; 100_000],
            vec![3],
            (0..60_000).map(|i| (i % 7) as u8).collect(),
        ] {
            assert_eq!(ours(&v), weezl(&v));
        }
        let mut empty = Vec::new();
        enc.encode_frame(&[], &mut empty);
        assert_eq!(empty, weezl(&[]));
    }
}
