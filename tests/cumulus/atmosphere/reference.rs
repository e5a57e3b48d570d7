//! The MetPy reference values of tests/reference/metpy/diagnostics_reference.txt
//! (written by diagnostics_reference.py beside it, run by hand with MetPy
//! 1.7.1) and the soundings they were computed on.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use cumulus::atmosphere::thermo::Thermo;
use cumulus::atmosphere::{Environment, Sounding};

pub fn path(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// The sounding at `rel` and its environment with the forecasters' thermodynamics.
pub fn standard_env(rel: &str) -> (Sounding, Environment) {
    let s = Sounding::load(&path(rel)).unwrap();
    let env = s.to_environment_with(Thermo::Standard).unwrap();
    (s, env)
}

/// MetPy's values by (sounding file name, key); NaN where MetPy has none.
/// The soundings are those the file's `# sounding PATH` lines name: the
/// two shipped ones, MetPy's jan20 and nov11 test soundings, and the
/// constructed high-plains (surface 842 hPa), tropical (no dewpoints above
/// 400 hPa, no wind) and capped ones.
pub struct Reference {
    values: HashMap<(String, String), f64>,
    pub soundings: Vec<String>,
}

impl Reference {
    pub fn load() -> Self {
        let text = std::fs::read_to_string(path("tests/reference/metpy/diagnostics_reference.txt"))
            .unwrap();
        let soundings = text
            .lines()
            .filter_map(|l| l.strip_prefix("# sounding "))
            .map(str::to_string)
            .collect();
        let values = text
            .lines()
            .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
            .map(|l| {
                let f: Vec<&str> = l.split_whitespace().collect();
                assert_eq!(f.len(), 3, "reference line {l:?}");
                ((f[0].to_string(), f[1].to_string()), f[2].parse().unwrap())
            })
            .collect();
        Reference { values, soundings }
    }

    /// The value of `key` on the sounding at `rel`, if MetPy gave one.
    pub fn get(&self, rel: &str, key: &str) -> Option<f64> {
        let name = Path::new(rel).file_name().unwrap().to_string_lossy();
        self.values
            .get(&(name.into_owned(), key.to_string()))
            .copied()
            .filter(|v| v.is_finite())
    }

    /// Like `get`, for a key every sounding has.
    pub fn value(&self, rel: &str, key: &str) -> f64 {
        self.get(rel, key)
            .unwrap_or_else(|| panic!("no reference {key} for {rel}"))
    }
}
