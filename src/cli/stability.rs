//! `cumulus stability`: runs the matrix of stiff and extreme cases with a
//! progress bar, prints the table, writes stability.md and stability.csv,
//! and exits non-zero if any case blew up.

use std::path::PathBuf;

use anyhow::bail;
use cumulus::stability::{self, Size};

/// Arguments of `cumulus stability`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The same kinds of case, smaller (about 10 s; the full matrix, with its
    /// 100 000-parcel cases, takes a few minutes).
    #[arg(long)]
    pub quick: bool,
    /// Directory for stability.md and stability.csv.
    #[arg(long, default_value = "stability-report")]
    pub out: PathBuf,
}

/// Runs `cumulus stability`.
pub fn run(args: Args) -> anyhow::Result<()> {
    // Fail before minutes of work if the report cannot be written.
    super::writable_folder("--out", &args.out)?;
    let size = if args.quick { Size::Quick } else { Size::Full };
    let cases = stability::matrix(size)?;
    let total: u64 = cases.iter().map(|c| c.frames as u64).sum();
    let bar = indicatif::ProgressBar::new(total);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{bar:40} {pos}/{len} frames  {msg}  [{elapsed_precise} < {eta_precise}]",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let mut done_before: Vec<u64> = Vec::with_capacity(cases.len());
    let mut acc = 0;
    for c in &cases {
        done_before.push(acc);
        acc += c.frames as u64;
    }
    let mut current = usize::MAX;
    let results = stability::run_matrix(&cases, |i, f| {
        if i != current {
            current = i;
            bar.set_message(cases[i].name.clone());
        }
        bar.set_position(done_before[i] + f as u64);
    });
    bar.finish_and_clear();

    let title = format!(
        "cumulus stability matrix ({})",
        if args.quick { "quick" } else { "full" }
    );
    let md = stability::to_markdown(&results, &title);
    println!("{md}");
    let [md_path, csv_path] = stability::write_reports(&args.out, &results, &title)?;
    eprintln!("wrote {} and {}", md_path.display(), csv_path.display());

    let failed: Vec<String> = results
        .iter()
        .filter(|r| !r.passed())
        .map(|r| format!("{}: {}", r.name, r.failures().join("; ")))
        .collect();
    if !failed.is_empty() {
        bail!(
            "{} of {} stability cases failed:\n  {}",
            failed.len(),
            results.len(),
            failed.join("\n  ")
        );
    }
    Ok(())
}
