//! The `cumulus` binary as a user runs it, and the checks the CLI tests make
//! on a run: it succeeded, or it failed cleanly (an error's exit status, a
//! message holding what the test expects), and in both cases it did not
//! panic.

use std::ffi::OsStr;
use std::process::{Command, Output};

/// The built binary, run in the crate root (so `profiles/...` resolves as
/// in the README). Add arguments, then [`run_command`] it.
pub fn command() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_cumulus"));
    c.current_dir(env!("CARGO_MANIFEST_DIR"));
    c
}

/// Runs `cumulus ARGS` to the end, capturing its output.
pub fn run<S: AsRef<OsStr>>(args: impl IntoIterator<Item = S>) -> Run {
    run_command(command().args(args))
}

/// Runs `command` (from [`command`]) to the end, capturing its output.
pub fn run_command(command: &mut Command) -> Run {
    let output = command
        .output()
        .unwrap_or_else(|e| panic!("cannot run {command:?}: {e}"));
    Run {
        command: format!("{command:?}"),
        output,
    }
}

/// A finished run of the binary.
pub struct Run {
    /// The command line, for messages.
    pub command: String,
    pub output: Output,
}

impl Run {
    pub fn succeeded(&self) -> bool {
        self.output.status.success()
    }

    pub fn stdout(&self) -> String {
        String::from_utf8_lossy(&self.output.stdout).into_owned()
    }

    pub fn stderr(&self) -> String {
        String::from_utf8_lossy(&self.output.stderr).into_owned()
    }

    /// The command, its status and everything it printed.
    fn report(&self) -> String {
        format!(
            "{}\n{}\n--- stdout\n{}\n--- stderr\n{}",
            self.command,
            self.output.status,
            self.stdout(),
            self.stderr()
        )
    }

    /// Panics when the binary panicked (Rust's panic message on stderr).
    pub fn assert_no_panic(&self) {
        assert!(
            !self.stderr().contains("panicked"),
            "panicked: {}",
            self.report()
        );
    }

    /// Checks that the run exited 0 without a panic; returns its stderr.
    pub fn expect_success(&self) -> String {
        assert!(self.succeeded(), "failed: {}", self.report());
        self.assert_no_panic();
        self.stderr()
    }

    /// Checks that the run failed cleanly: exit status 1 (the program's
    /// error) or 2 (clap's usage error), never 101 (a panic) or 134 (an
    /// abort), no panic message, and stderr holding every one of `expect`.
    /// Returns stderr.
    pub fn expect_failure_containing(&self, expect: &[&str]) -> String {
        assert!(!self.succeeded(), "succeeded: {}", self.report());
        let code = self.output.status.code();
        assert!(
            matches!(code, Some(1) | Some(2)),
            "exit {code:?}: {}",
            self.report()
        );
        self.assert_no_panic();
        let stderr = self.stderr();
        for e in expect {
            assert!(stderr.contains(e), "{e:?} not in stderr: {}", self.report());
        }
        stderr
    }
}
