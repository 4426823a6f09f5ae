//! STEP input never panics: the STEP fixtures (the `step` fuzz target's seeds) replayed, and
//! deterministic mutations of them — every truncation on a stride, byte substitutions and
//! swapped references — which reach the mappers behind the parser (the fuzzer proper is
//! `cd fuzz && cargo fuzz run step corpus/step ../crates/cam/tests/fixtures`).

use std::path::{Path, PathBuf};

use tezgah_cam::step;

fn corpus() -> Vec<(PathBuf, Vec<u8>)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures");
    let mut out: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "stp"))
        .map(|p| {
            let bytes = std::fs::read(&p).unwrap();
            (p, bytes)
        })
        .collect();
    out.sort();
    out
}

#[test]
fn corpus_never_panics() {
    let files = corpus();
    assert!(files.len() >= 5);
    for (path, bytes) in files {
        let r = std::panic::catch_unwind(|| step::fuzz(&bytes));
        assert!(r.is_ok(), "{} panics", path.display());
    }
}

/// A small deterministic generator (SplitMix64), so a failure names a reproducible case.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

#[test]
fn mutated_fixtures_never_panic() {
    const ALPHABET: &[u8] = b"#0123456789(),;.'$*=-E \nABTF";
    let mut rng = Rng(7);
    for (path, bytes) in corpus() {
        if bytes.len() > 20_000 {
            continue; // the blade: same entity kinds as the others, 5× the time
        }
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        for cut in (0..bytes.len()).step_by(211) {
            let r = std::panic::catch_unwind(|| step::fuzz(&bytes[..cut]));
            assert!(r.is_ok(), "{name} truncated at {cut} panics");
        }
        for case in 0..200 {
            let mut m = bytes.clone();
            for _ in 0..1 + rng.below(4) {
                let at = rng.below(m.len());
                m[at] = ALPHABET[rng.below(ALPHABET.len())];
            }
            let r = std::panic::catch_unwind(|| step::fuzz(&m));
            assert!(r.is_ok(), "{name} mutation {case} panics");
        }
        // References redirected at random: cycles, wrong entity kinds, self-references.
        let text = String::from_utf8_lossy(&bytes).into_owned();
        for case in 0..80 {
            let mut out = String::with_capacity(text.len());
            for (k, piece) in text.split('#').enumerate() {
                if k > 0 {
                    out.push('#');
                    if rng.below(8) == 0 {
                        let digits = piece.bytes().take_while(u8::is_ascii_digit).count();
                        if digits > 0 {
                            out.push_str(&(1 + rng.below(200)).to_string());
                            out.push_str(&piece[digits..]);
                            continue;
                        }
                    }
                }
                out.push_str(piece);
            }
            let r = std::panic::catch_unwind(|| step::fuzz(out.as_bytes()));
            assert!(r.is_ok(), "{name} reference shuffle {case} panics");
        }
    }
}
