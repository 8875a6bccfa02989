//! The `--start` value of `initiate` and `animate`: `ground` or `air` in any case, as the other
//! word flags take theirs (`--species`, `--phase`, `--glide`, `--kind`, `--keys`), or else the
//! path of a start file. A value that is neither a start word nor a path of an existing file
//! (`--start grund`) is refused at once, naming the words, instead of failing later as a missing
//! file. A start file named like a word is given as a path (`./ground`).

use std::path::Path;

use formation::initiate::{GroundStart, Start, StartRegion};

/// The words of the starts that are not files, as the library names them.
fn words() -> [&'static str; 2] {
    [
        Start::Ground(GroundStart::default()).word(),
        Start::Random(StartRegion::default()).word(),
    ]
}

/// clap's parser of `--start`: a start word in the library's spelling, or the path as given.
pub fn parse_start(value: &str) -> Result<String, String> {
    let [ground, air] = words();
    if let Some(w) = words()
        .into_iter()
        .find(|w| value.trim().eq_ignore_ascii_case(w))
    {
        return Ok(w.to_string());
    }
    // Anything with a directory or an extension is meant as a file (a missing one is reported
    // with its name when it is read); a bare word is a file only if there is one.
    if value.contains(['/', '.']) || Path::new(value).exists() {
        return Ok(value.to_string());
    }
    Err(format!(
        "unknown start; use {ground}, {air} or a start file (no file of that name exists)"
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn start_words_in_any_case_paths_as_given_others_refused() {
        for (given, want) in [
            ("ground", "ground"),
            ("GROUND", "ground"),
            (" Air ", "air"),
            ("starts/s.json", "starts/s.json"),
            ("s.json", "s.json"),
        ] {
            assert_eq!(parse_start(given).as_deref(), Ok(want), "{given}");
        }
        for bad in ["grund", "GRUND", "sky", ""] {
            let e = parse_start(bad).unwrap_err();
            assert!(e.contains("ground, air or a start file"), "{bad}: {e}");
        }
    }
}
