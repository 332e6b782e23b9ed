//! The recorder's `--rrd FILE` in a launch file's services: dropped where no Rerun file is
//! wanted (a sweep, a replay without `--rrd`), given where one is wanted of a recording made
//! without it (a replay with `--rrd` of a sweep's run).

/// Whether `s` is the recorder.
fn is_recorder(s: &toml::Value) -> bool {
    super::replay_launch::binary_of(s) == "harvey-recorder"
}

/// The recorder's arguments, if it has any.
fn recorder_args(services: &mut [toml::Value]) -> impl Iterator<Item = &mut Vec<toml::Value>> {
    services.iter_mut().filter(|s| is_recorder(s)).filter_map(|s| s.get_mut("args")?.as_array_mut())
}

/// Drops the recorder's `--rrd FILE` (or `--rrd=FILE`).
pub fn drop_rrd(services: &mut [toml::Value]) {
    for args in recorder_args(services) {
        if let Some(at) = args.iter().position(|a| a.as_str() == Some("--rrd")) {
            args.drain(at..(at + 2).min(args.len()));
        }
        args.retain(|a| !a.as_str().is_some_and(|a| a.starts_with("--rrd=")));
    }
}

/// Gives the recorder `--rrd path` unless it draws one already.
pub fn ensure_rrd(services: &mut [toml::Value], path: &str) {
    for args in recorder_args(services) {
        if !args.iter().any(|a| a.as_str().is_some_and(|a| a == "--rrd" || a.starts_with("--rrd="))) {
            args.extend(["--rrd".into(), path.into()]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn services(text: &str) -> Vec<toml::Value> {
        let doc: toml::Table = toml::from_str(text).expect("toml");
        doc["service"].as_array().expect("services").clone()
    }

    fn args(s: &toml::Value) -> Vec<&str> {
        s["args"].as_array().expect("args").iter().filter_map(toml::Value::as_str).collect()
    }

    #[test]
    fn only_the_recorder_loses_or_gains_its_rerun_file() {
        let mut s = services(
            r#"
            [[service]]
            name = "recorder"
            args = ["--output", "o.mcap", "--rrd", "o.rrd", "--world", "w"]
            [[service]]
            name = "viewer"
            binary = "my-viewer"
            args = ["--rrd", "--fast"]
            "#,
        );
        drop_rrd(&mut s);
        assert_eq!(args(&s[0]), ["--output", "o.mcap", "--world", "w"]);
        assert_eq!(args(&s[1]), ["--rrd", "--fast"], "not the recorder: untouched");
        ensure_rrd(&mut s, "${run_dir}/run.rrd");
        assert_eq!(args(&s[0]), ["--output", "o.mcap", "--world", "w", "--rrd", "${run_dir}/run.rrd"]);
        ensure_rrd(&mut s, "other.rrd");
        assert_eq!(args(&s[0]).len(), 6, "one Rerun file, not two");
        let mut eq = services("[[service]]\nname = \"recorder\"\nargs = [\"--rrd=x.rrd\", \"--rrd\"]");
        drop_rrd(&mut eq);
        assert!(args(&eq[0]).is_empty(), "{:?}", args(&eq[0]));
    }
}
