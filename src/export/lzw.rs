//! GIF's LZW compression with a fast path for runs (issue 14).
//!
//! The GIF frames this crate writes are mostly runs: the transparent index where a frame
//! did not change, flat paper shades where it did. A byte-at-a-time LZW encoder (the
//! `gif` crate's, `weezl`) walks its dictionary once per byte, and that was a fifth of
//! the samples of a profile of a search with export. Along a run of one byte `s` greedy LZW only ever extends strings
//! `s, ss, sss, …`, and the dictionary always holds a prefix-closed chain of them, so a
//! run of length L is `O(√L)` steps here: jump to the longest `sᵏ` the run covers, emit it,
//! add `sᵏ⁺¹`. Everything else is the textbook encoder with an open-addressing table.
//!
//! The stream is textbook greedy LZW with GIF's rules (the minimum code size the `gif`
//! crate picks, a clear code first, a wider code when the next needs another bit, a clear
//! after entry 4095, the end code), so [`gif::Encoder::write_lzw_pre_encoded_frame`] takes
//! it; `tests` checks it bit for bit against a one-lookup-per-byte encoder and reads it
//! back with the `gif` crate's decoder. (The `gif` crate's own encoder now and then misses
//! an entry it has and writes a few per cent more on some inputs; both decode the same.)

/// The largest code width GIF allows.
const MAX_BITS: u8 = 12;
/// Dictionary entries before a clear (`1 << MAX_BITS`).
const MAX_ENTRIES: usize = 1 << MAX_BITS;
/// Slots of the open-addressing table: a power of two, at least twice the entries.
const SLOTS: usize = 1 << 14;

/// `data` (palette indices) compressed as one GIF image's data: the minimum code size
/// byte, then the LSB-first code stream from the first clear code to the end code, as
/// `gif::Frame::make_lzw_pre_encoded` writes it.
pub fn encode(data: &[u8]) -> Vec<u8> {
    // The minimum code size the `gif` crate picks: enough for the largest index, ≥ 2.
    let max = data.iter().copied().max().unwrap_or(0);
    let min_size = (u32::from(max) + 1)
        .max(4)
        .next_power_of_two()
        .trailing_zeros() as u8;
    let mut out = Vec::with_capacity(data.len() / 4 + 16);
    out.push(min_size);
    // The tables (2 MiB of run chains) are kept per thread: a GIF has dozens of frames.
    thread_local! {
        static TABLES: std::cell::RefCell<Option<Tables>> = const { std::cell::RefCell::new(None) };
    }
    TABLES.with(|t| {
        let mut t = t.borrow_mut();
        let tables = t.get_or_insert_with(Tables::new);
        Encoder::new(min_size, out, tables).run(data)
    })
}

/// The dictionary's storage, reused from stream to stream.
struct Tables {
    /// `(prefix << 8 | byte) << 12 | code` per occupied slot, 0 for empty (no entry has
    /// code 0: codes below `clear + 2` are never added).
    table: Vec<u32>,
    /// `run_len[s]`: the longest `sᵏ` in the dictionary; `run_code[s][k − 1]` its code.
    run_len: [u16; 256],
    run_code: Vec<u16>,
}

impl Tables {
    fn new() -> Tables {
        let mut run_code = vec![0; 256 * MAX_ENTRIES];
        for s in 0..256 {
            run_code[s * MAX_ENTRIES] = s as u16;
        }
        Tables {
            table: vec![0; SLOTS],
            run_len: [1; 256],
            run_code,
        }
    }

    /// Empty the dictionary (the roots stay: `run_code[s][0] = s`).
    fn clear(&mut self) {
        self.table.fill(0);
        self.run_len = [1; 256];
    }
}

/// The state of one stream.
struct Encoder<'a> {
    min_size: u8,
    clear: u16,
    /// The next code the dictionary assigns (`clear + 2` after a clear).
    next: usize,
    /// Bits per code now.
    size: u8,
    t: &'a mut Tables,
    bits: u64,
    nbits: u8,
    out: Vec<u8>,
}

impl Encoder<'_> {
    fn new(min_size: u8, out: Vec<u8>, t: &mut Tables) -> Encoder<'_> {
        let clear = 1u16 << min_size;
        t.clear();
        let mut e = Encoder {
            min_size,
            clear,
            next: usize::from(clear) + 2,
            size: min_size + 1,
            t,
            bits: 0,
            nbits: 0,
            out,
        };
        e.put(clear);
        e
    }

    #[inline]
    fn put(&mut self, code: u16) {
        self.bits |= u64::from(code) << self.nbits;
        self.nbits += self.size;
        while self.nbits >= 8 {
            self.out.push(self.bits as u8);
            self.bits >>= 8;
            self.nbits -= 8;
        }
    }

    #[inline]
    fn slot(key: u32) -> usize {
        (key.wrapping_mul(0x9E37_79B1) >> (32 - SLOTS.trailing_zeros())) as usize
    }

    /// The code of string `prefix` + `byte`, if the dictionary has it.
    #[inline]
    fn find(&self, prefix: u16, byte: u8) -> Option<u16> {
        let key = (u32::from(prefix) << 8) | u32::from(byte);
        let mut i = Self::slot(key);
        loop {
            let e = self.t.table[i];
            if e == 0 {
                return None;
            }
            if e >> 12 == key {
                return Some((e & 0xfff) as u16);
            }
            i = (i + 1) & (SLOTS - 1);
        }
    }

    /// Emit `code` for the current string and add `code` + `byte` to the dictionary
    /// (`run`: the string is `byteᵏ` with k = `run_len[byte]`), then widen the codes or
    /// clear by GIF's rules.
    fn emit_and_add(&mut self, code: u16, byte: u8, run: bool) {
        let new = self.next;
        self.next += 1;
        if new < MAX_ENTRIES {
            let key = (u32::from(code) << 8) | u32::from(byte);
            let mut i = Self::slot(key);
            while self.t.table[i] != 0 {
                i = (i + 1) & (SLOTS - 1);
            }
            self.t.table[i] = (key << 12) | new as u32;
            if run {
                let s = usize::from(byte);
                let k = usize::from(self.t.run_len[s]);
                self.t.run_code[s * MAX_ENTRIES + k] = new as u16;
                self.t.run_len[s] += 1;
            }
        }
        self.put(code);
        if self.next > 1 << self.size && self.size < MAX_BITS {
            self.size += 1;
        }
        if self.next > MAX_ENTRIES {
            self.put(self.clear);
            self.t.clear();
            self.next = usize::from(self.clear) + 2;
            self.size = self.min_size + 1;
        }
    }

    fn run(mut self, data: &[u8]) -> Vec<u8> {
        let Some((&first, _)) = data.split_first() else {
            self.put(self.clear + 1);
            return self.finish();
        };
        // The current string: its code, and `Some(k)` while it is `sᵏ` for its first byte s.
        let mut code = u16::from(first);
        let mut sym = first;
        let mut run: Option<usize> = Some(1);
        // Where the run of `sym` that position i is in ends: measured once per run, not
        // once per step along it (that made a run of length L cost L^1.5).
        let mut run_end = 0;
        let mut i = 1;
        while i < data.len() {
            let b = data[i];
            if let (Some(k), true) = (run, b == sym) {
                let s = usize::from(sym);
                if i >= run_end || data[run_end - 1] != sym {
                    run_end = i + run_length(&data[i..], sym);
                }
                let len = run_end - i;
                let have = usize::from(self.t.run_len[s]);
                if k + len <= have {
                    // The whole run extends the string within the dictionary.
                    code = self.t.run_code[s * MAX_ENTRIES + k + len - 1];
                    run = Some(k + len);
                    i += len;
                    continue;
                }
                // Extend to the longest sᵏ, then the next s fails to extend it.
                i += have - k;
                let longest = self.t.run_code[s * MAX_ENTRIES + have - 1];
                self.emit_and_add(longest, sym, true);
                code = u16::from(sym);
                run = Some(1);
                i += 1;
                continue;
            }
            match self.find(code, b) {
                Some(c) => {
                    code = c;
                    run = None;
                }
                None => {
                    self.emit_and_add(code, b, false);
                    code = u16::from(b);
                    sym = b;
                    run = Some(1);
                }
            }
            i += 1;
        }
        self.put(code);
        // The decoder adds one more entry on reading that code and may widen first.
        if self.next >= 1 << self.size && self.size < MAX_BITS {
            self.size += 1;
        }
        self.put(self.clear + 1);
        self.finish()
    }

    fn finish(mut self) -> Vec<u8> {
        if self.nbits > 0 {
            self.out.push(self.bits as u8);
        }
        self.out
    }
}

/// How many bytes at the start of `data` equal `s` (8 at a time).
#[inline]
fn run_length(data: &[u8], s: u8) -> usize {
    let pattern = u64::from_ne_bytes([s; 8]);
    let mut n = 0;
    let mut chunks = data.chunks_exact(8);
    for c in chunks.by_ref() {
        let x = u64::from_le_bytes(c.try_into().unwrap_or([0; 8])) ^ pattern;
        if x != 0 {
            return n + (x.trailing_zeros() / 8) as usize;
        }
        n += 8;
    }
    n + chunks.remainder().iter().take_while(|&&b| b == s).count()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    /// Textbook greedy LZW with GIF's rules (clear first, widen when the next code needs
    /// another bit, clear after entry 4095, end code), one dictionary lookup per byte and
    /// no run path: what [`encode`] must write bit for bit.
    fn textbook(data: &[u8]) -> Vec<u8> {
        let max = data.iter().copied().max().unwrap_or(0);
        let min_size = (u32::from(max) + 1)
            .max(4)
            .next_power_of_two()
            .trailing_zeros() as u8;
        let clear = 1u32 << min_size;
        let mut codes: Vec<(u32, u8)> = Vec::new();
        let (mut dict, mut next, mut size) = (HashMap::new(), clear + 2, min_size + 1);
        codes.push((clear, size));
        if let Some((&first, rest)) = data.split_first() {
            let mut w = u32::from(first);
            for &b in rest {
                if let Some(&c) = dict.get(&(w, b)) {
                    w = c;
                    continue;
                }
                dict.insert((w, b), next);
                next += 1;
                codes.push((w, size));
                if next > 1 << size && size < 12 {
                    size += 1;
                }
                if next > 4096 {
                    codes.push((clear, size));
                    dict.clear();
                    next = clear + 2;
                    size = min_size + 1;
                }
                w = u32::from(b);
            }
            codes.push((w, size));
            if next >= 1 << size && size < 12 {
                size += 1;
            }
        }
        codes.push((clear + 1, size));
        let mut out = vec![min_size];
        let (mut bits, mut n) = (0u64, 0u8);
        for (c, s) in codes {
            bits |= u64::from(c) << n;
            n += s;
            while n >= 8 {
                out.push(bits as u8);
                bits >>= 8;
                n -= 8;
            }
        }
        if n > 0 {
            out.push(bits as u8);
        }
        out
    }

    /// A deterministic byte generator (xorshift), so the cases are the same every run.
    fn bytes(seed: u64, n: usize, f: impl Fn(u64) -> u8) -> Vec<u8> {
        let mut x = seed | 1;
        (0..n)
            .map(|_| {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                f(x)
            })
            .collect()
    }

    /// Inputs: empty, single bytes, long runs, random bytes over every minimum code size
    /// (dictionaries filling and clearing many times), runs of random lengths mixed with
    /// noise as the frames have them, and long runs of three symbols.
    fn cases() -> Vec<Vec<u8>> {
        let mut cases: Vec<Vec<u8>> = vec![
            vec![],
            vec![7],
            vec![200],
            vec![3; 2],
            vec![255; 100_000],
            vec![0; 65_535],
        ];
        for (seed, range) in [(1u64, 4u64), (2, 16), (3, 100), (4, 128), (5, 256)] {
            cases.push(bytes(seed, 60_000, |x| (x % range) as u8));
        }
        for seed in 6..12u64 {
            let mut v = Vec::new();
            let mut r = bytes(seed, 4000, |x| x as u8).into_iter();
            while v.len() < 120_000 {
                let (Some(s), Some(l), Some(k)) = (r.next(), r.next(), r.next()) else {
                    break;
                };
                let len = if k % 3 == 0 {
                    usize::from(l) * 40
                } else {
                    usize::from(l % 9)
                };
                v.extend(std::iter::repeat_n(s % 24 + 200, len));
                v.push(k);
            }
            cases.push(v);
        }
        cases.push(
            bytes(12, 3000, |x| (x % 3) as u8)
                .into_iter()
                .flat_map(|b| std::iter::repeat_n(b, 97))
                .collect(),
        );
        cases
    }

    #[test]
    fn the_stream_is_textbook_lzw_bit_for_bit() {
        for (k, data) in cases().iter().enumerate() {
            let (ours, want) = (encode(data), textbook(data));
            let first = ours.iter().zip(&want).position(|(a, b)| a != b);
            assert!(
                ours == want,
                "case {k}, {} bytes: {} against {} bytes, first difference at {first:?}",
                data.len(),
                ours.len(),
                want.len()
            );
        }
    }

    #[test]
    fn the_gif_crates_decoder_reads_back_the_input() {
        for (k, data) in cases().iter().enumerate() {
            let stream = encode(data);
            let mut dec = weezl::decode::Decoder::new(weezl::BitOrder::Lsb, stream[0]);
            let back = dec.decode(&stream[1..]).expect("a valid LZW stream");
            assert!(
                back == *data,
                "case {k}: {} bytes back of {}",
                back.len(),
                data.len()
            );
        }
    }

    #[test]
    fn run_length_counts_the_leading_equal_bytes() {
        let mut v = vec![9u8; 37];
        v.push(1);
        v.extend([9; 5]);
        for start in 0..v.len() {
            let want = v[start..].iter().take_while(|&&b| b == 9).count();
            assert_eq!(run_length(&v[start..], 9), want, "from {start}");
        }
        assert_eq!(run_length(&[], 9), 0);
    }
}
