//! Work spread over rayon's threads whose result is the same, to the bit, for any number of
//! them.

use std::ops::AddAssign;

use rayon::prelude::*;

/// Terms [`ordered_sum`] holds at a time (8 MB of `f64`).
const SUM_BLOCK: usize = 1 << 20;

/// `Σ term(i)` for `i` in `0..n`, added one by one in index order from `T::default()` as a
/// serial loop adds them, so with the same bits for any thread count; the terms are computed on
/// every thread, a block at a time. (Millions of triangles' areas took a tenth of a second on
/// one thread.)
pub(crate) fn ordered_sum<T>(n: usize, term: impl Fn(usize) -> T + Sync) -> T
where
    T: Copy + Default + Send + AddAssign,
{
    ordered_sum_in_blocks(n, SUM_BLOCK, term)
}

/// [`ordered_sum`] with `block` terms at a time.
fn ordered_sum_in_blocks<T>(n: usize, block: usize, term: impl Fn(usize) -> T + Sync) -> T
where
    T: Copy + Default + Send + AddAssign,
{
    let mut total = T::default();
    let mut terms = Vec::with_capacity(n.min(block));
    for start in (0..n).step_by(block.max(1)) {
        terms.clear();
        terms.par_extend((start..n.min(start + block)).into_par_iter().map(&term));
        for &t in &terms {
            total += t;
        }
    }
    total
}

/// Items per task of [`first_where`]. Rayon's own search (`position_first`) splits down to
/// single items and checks the other tasks' progress at each: on 7.8 M index triples it took
/// 0.06 s on two threads, a serial loop 0.013 s, these chunks 0.014–0.017 s (a check that
/// only reads is bound by memory; one that computes, such as a normal's length, gains).
const SEARCH_CHUNK: usize = 1 << 14;

/// The index of the first item of `items` for which `pred` holds, looked for on every thread.
pub(crate) fn first_where<T: Sync>(items: &[T], pred: impl Fn(&T) -> bool + Sync) -> Option<usize> {
    let chunk = items
        .par_chunks(SEARCH_CHUNK)
        .position_first(|chunk| chunk.iter().any(&pred))?;
    let start = chunk * SEARCH_CHUNK;
    items[start..].iter().position(&pred).map(|i| start + i)
}

/// `(key(i), i)` for every `i < len`, sorted, the keys computed and sorted on every thread.
/// The index makes every entry distinct, so the unstable sort gives one order for any number
/// of threads, entries of one key in index order. Items to leave out get a key above every
/// other and are cut off after the sort by the caller: the collect here is indexed and writes
/// in place, where a filtered one gathered pieces and copied them (twice the memory).
pub(crate) fn sorted_by_key(len: usize, key: impl Fn(usize) -> u64 + Sync) -> Vec<(u64, u32)> {
    let mut keyed: Vec<(u64, u32)> = (0..len)
        .into_par_iter()
        .map(|i| (key(i), i as u32))
        .collect();
    keyed.par_sort_unstable();
    keyed
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::raster::testutil::Rng;

    /// Keyed entries sorted on any number of threads are the stable serial sort's: by key,
    /// then by index among equal keys.
    #[test]
    fn sorted_by_key_is_the_stable_serial_sort() {
        let mut rng = Rng::new(3);
        let keys: Vec<u64> = (0..20_000).map(|_| rng.next_u64() % 500).collect();
        let mut serial: Vec<(u64, u32)> = (0..keys.len() as u32)
            .map(|i| (keys[i as usize], i))
            .collect();
        serial.sort_by_key(|&(k, _)| k);
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let sorted = pool.install(|| sorted_by_key(keys.len(), |i| keys[i]));
            assert_eq!(sorted, serial, "{threads} threads");
        }
    }

    /// The sum in blocks on any number of threads has the bits of the serial loop, on terms
    /// of every magnitude (where the order of the additions shows in the result).
    #[test]
    fn ordered_sum_has_the_serial_bits() {
        let mut rng = Rng::new(11);
        let terms: Vec<f64> = (0..5000)
            .map(|_| (rng.f32_in(0.0, 1.0) as f64) * 10f64.powi(rng.f32_in(-8.0, 8.0) as i32))
            .collect();
        let mut serial = 0.0;
        for &t in &terms {
            serial += t;
        }
        // A different order gives other bits on these terms, so the test can tell.
        assert_ne!(terms.iter().rev().sum::<f64>().to_bits(), serial.to_bits());
        let vectors: Vec<DVec3> = terms.chunks_exact(3).map(DVec3::from_slice).collect();
        let serial_vector = vectors.iter().fold(DVec3::ZERO, |s, &v| s + v);
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            for block in [1, 7, 64, 4999, 5000, 100_000] {
                let sum = pool.install(|| ordered_sum_in_blocks(terms.len(), block, |i| terms[i]));
                assert_eq!(
                    sum.to_bits(),
                    serial.to_bits(),
                    "{threads} threads, blocks of {block}"
                );
                let sum =
                    pool.install(|| ordered_sum_in_blocks(vectors.len(), block, |i| vectors[i]));
                assert_eq!(
                    sum.to_array().map(f64::to_bits),
                    serial_vector.to_array().map(f64::to_bits)
                );
            }
        }
        assert_eq!(ordered_sum(0, |_| 1.0), 0.0);
    }

    /// The first match in index order, wherever the chunks and threads cut the items: matches
    /// at chunk edges, several in one chunk, later ones where other threads start, none.
    #[test]
    fn first_where_finds_the_first_match() {
        let n = 5 * SEARCH_CHUNK + 17;
        for marked in [
            vec![0],
            vec![n - 1],
            vec![SEARCH_CHUNK - 1, SEARCH_CHUNK],
            vec![3 * SEARCH_CHUNK + 5, 3 * SEARCH_CHUNK + 9, SEARCH_CHUNK * 4],
            vec![2 * SEARCH_CHUNK + 1, n / 2 + 1, n - 2],
            vec![],
        ] {
            let mut items = vec![false; n];
            for &k in &marked {
                items[k] = true;
            }
            for threads in [1, 2, 3] {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap();
                let found = pool.install(|| first_where(&items, |&b| b));
                assert_eq!(
                    found,
                    marked.first().copied(),
                    "{marked:?}, {threads} threads"
                );
            }
        }
        assert_eq!(first_where(&[] as &[u8], |_| true), None);
    }
}
