//! The Python environment: a venv in `target/py-client-venv`, made once per test binary, with
//! the package freshly installed from the checkout, and the client run in it.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use crate::common;

/// The venv's Python with the package freshly installed, made once per test binary.
pub fn python() -> &'static Path {
    static PYTHON: OnceLock<PathBuf> = OnceLock::new();
    PYTHON.get_or_init(|| {
        let venv = common::bin_dir().parent().expect("target folder").join("py-client-venv");
        let python = venv.join("bin").join("python");
        let run = |what: &str, cmd: &mut Command| {
            let out = cmd.output().unwrap_or_else(|e| panic!("{what}: cannot start: {e}"));
            assert!(
                out.status.success(),
                "{what} failed ({}): the Python client test needs python3 with venv and, on the \
                 first run, network access to PyPI (iceoryx2==0.10.0, numpy)\n{}\n{}",
                out.status,
                String::from_utf8_lossy(&out.stdout),
                String::from_utf8_lossy(&out.stderr)
            );
        };
        if !python.is_file() {
            run("python3 -m venv", Command::new("python3").args(["-m", "venv"]).arg(&venv));
        }
        let pip = |args: &[&str]| {
            let mut c = Command::new(&python);
            c.args(["-m", "pip", "install", "--quiet", "--disable-pip-version-check"]).args(args);
            c
        };
        // The dependencies (a no-op once they are there, network or not), then the package
        // itself, built with the venv's setuptools so that reinstalling needs no network.
        run(
            "pip install of the dependencies",
            &mut pip(&["setuptools>=61", "wheel", "iceoryx2==0.10.0", "numpy"]),
        );
        run(
            "pip install ./python/harvey_client",
            pip(&["--no-build-isolation", "--force-reinstall", "--no-deps"])
                .arg(common::repo().join("python").join("harvey_client")),
        );
        python
    })
}

/// `python -m harvey_client ARGS` in the venv.
pub fn client(args: &[&str]) -> Command {
    let mut c = Command::new(python());
    c.args(["-m", "harvey_client"]).args(args).current_dir(common::repo());
    c
}
