//! A Monte Carlo table built in shards (a Slurm job array) and combined equals the table built on one
//! machine, byte for byte: the shards trace the same photons (per stratum a range of chunks, each
//! with its own random stream) and their tallies are exact sums, added in any order and rounded
//! once. A set of parts with a shard missing, given twice, or made for another spec is refused.
//! Fixed seeds; a small table (coarse photons, 16 albedos) so that the test takes seconds.

use scatterfit_mc::white::WhitePartial;
use scatterfit_mc::{McError, McTable, McTableSpec, Shard};

fn spec(g: f64) -> McTableSpec {
    let mut s = McTableSpec::coarse(1.3, g).unwrap();
    s.albedo_count = 16;
    // Coarse photons leave the lowest albedos at g = 0.9 too little light to smooth.
    s.albedo_min = if g > 0.5 { 0.9 } else { 0.02 };
    s.seed = 7;
    if g > 0.5 {
        // Low-albedo nodes from their own run, which the combination adds (as one machine does).
        s = s.with_low_albedos_to(0.5, 400_000).unwrap();
    }
    s
}

fn parts(spec: &McTableSpec, n: u64) -> Vec<WhitePartial> {
    (1..=n)
        .map(|k| McTable::build_shard(spec, Shard::new(k, n).unwrap(), &|_, _| {}).unwrap())
        .collect()
}

fn bytes(t: &McTable) -> Vec<u8> {
    serde_json::to_vec(t).unwrap()
}

/// One machine against 3 and 8 shards (8 at g = 0.9: the CI's Slurm case), combined in scrambled
/// orders, with the raw tallies compared too (the JSON keeps them), and through the partial files'
/// JSON (serde_json's float_roundtrip keeps every component exactly).
#[test]
fn shards_combine_to_the_one_machine_table_byte_for_byte() {
    for (g, n) in [(0.0, 3), (0.9, 8)] {
        let spec = spec(g);
        let whole = McTable::build(&spec, &|_, _| {}).unwrap();
        let mut p = parts(&spec, n);
        // Through JSON, as the partial files carry them.
        p = p
            .iter()
            .map(|x| serde_json::from_str(&serde_json::to_string(x).unwrap()).unwrap())
            .collect();
        p.reverse();
        p.swap(0, 1);
        let merged = McTable::combine(&spec, &p).unwrap();
        assert!(whole.raw().is_some());
        // (assert!, not assert_eq!: a failure should not print two tables' bytes.)
        assert!(
            bytes(&merged) == bytes(&whole),
            "g = {g}: {n} shards combined differ from the one-machine table"
        );
        assert!(
            serde_json::to_vec(&merged.clone().compact()).unwrap()
                == serde_json::to_vec(&whole.clone().compact()).unwrap()
        );
        // The shards' photons add up to the run's.
        let white = spec.white().unwrap();
        let sum: u64 = (1..=n)
            .map(|k| white.shard_photons(Shard::new(k, n).unwrap()))
            .sum();
        assert_eq!(sum, white.photons());
    }
}

fn refused(spec: &McTableSpec, p: &[WhitePartial], what: &str) {
    match McTable::combine(spec, p) {
        Err(McError::Shards { message }) => {
            assert!(message.contains(what), "{message:?} should say {what:?}")
        }
        other => panic!("expected a refusal naming {what:?}, got {other:?}"),
    }
}

#[test]
fn incomplete_duplicated_or_foreign_sets_are_refused() {
    let spec = spec(0.0);
    let p = parts(&spec, 3);
    refused(&spec, &p[..2], "3/3 missing");
    refused(
        &spec,
        &[p[0].clone(), p[1].clone(), p[1].clone()],
        "2/3 is given twice",
    );
    // A shard of another seed (a foreign run).
    let mut other = spec.clone();
    other.seed = 8;
    let foreign = McTable::build_shard(&other, Shard::new(3, 3).unwrap(), &|_, _| {}).unwrap();
    refused(
        &spec,
        &[p[0].clone(), p[1].clone(), foreign],
        "another table spec",
    );
    // A part whose sums were damaged (a component zeroed).
    let mut damaged = p[2].clone();
    let cell = damaged.strata[0]
        .w
        .iter_mut()
        .find(|s| !s.components().is_empty())
        .unwrap();
    *cell = serde_json::from_str("[0.0]").unwrap();
    refused(
        &spec,
        &[p[0].clone(), p[1].clone(), damaged],
        "not a valid exact sum",
    );
    // A shard of a 4-way split among 3-way ones.
    let four = McTable::build_shard(&spec, Shard::new(3, 4).unwrap(), &|_, _| {}).unwrap();
    refused(
        &spec,
        &[p[0].clone(), p[1].clone(), four],
        "not one of 3 shards",
    );
}

/// A stratum of more than 1024 chunks (2.2·10⁶ photons, stopped at 16 interactions: cheap) is
/// summed in groups of chunks (⌈chunks/1024⌉ = 2 here) before the exact additions; shards start
/// at group boundaries, so 3 and 7 shards still give the one run's tally bit for bit.
#[test]
fn grouped_chunks_shard_exactly() {
    use scatterfit_mc::white::{combine, simulate, simulate_shard};
    let mut spec = McTableSpec::with_strata(1.3, 0.0, vec![2_200_000, 20_000], vec![16]).unwrap();
    spec.albedo_count = 8;
    let white = spec.white().unwrap();
    let whole = simulate(&white, &|_| {}).unwrap();
    for n in [3, 7] {
        let mut parts: Vec<_> = (1..=n)
            .map(|k| simulate_shard(&white, Shard::new(k, n).unwrap(), &|_| {}).unwrap())
            .collect();
        // Each shard's range of the big stratum starts at a group boundary (2 chunks): a group's
        // f64 sum is the same in every split. (A misaligned split would round differently only
        // rarely — the final rounding absorbs most of it — so the invariant is checked itself.)
        for p in &parts {
            let [start, end] = p.strata[0].chunks;
            assert!(
                start % 2 == 0 && (end % 2 == 0 || end == 1075),
                "{start}..{end}"
            );
        }
        parts.rotate_left(1);
        let merged = combine(&parts).unwrap();
        assert!(merged == whole, "{n} shards differ from the one run");
        let photons: u64 = (1..=n)
            .map(|k| white.shard_photons(Shard::new(k, n).unwrap()))
            .sum();
        assert_eq!(photons, white.photons());
    }
}
