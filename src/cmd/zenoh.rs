//! `--zenoh-listen` / `--zenoh-connect`: the Zenoh bridge (`harvey-zenoh-bridge`,
//! `docs/zenoh.md`) added to a launch as one more service that exports every topic, so that a
//! process on another host (or another domain) can watch the run.

/// The Zenoh bridge's service name (its binary: `harvey-zenoh-bridge`, beside `harvey`).
pub const ZENOH_SERVICE: &str = "zenoh-bridge";

/// The bridge exporting every topic on the endpoints given. In a deterministic launch it is a
/// clock party, so each tick's messages are on Zenoh before the next tick starts.
pub fn zenoh_service(
    listen: &[String],
    connect: &[String],
    ros2_domain: Option<u32>,
) -> anyhow::Result<harvey_supervisor::config::Service> {
    let mut args = vec!["--export".to_owned(), "all".to_owned()];
    if let Some(d) = ros2_domain {
        args.extend(["--ros2-domain".to_owned(), d.to_string()]);
    }
    for e in listen {
        args.extend(["--zenoh-listen".to_owned(), e.clone()]);
    }
    for e in connect {
        args.extend(["--zenoh-connect".to_owned(), e.clone()]);
    }
    let quoted: Vec<String> = args.into_iter().map(|a| toml::Value::String(a).to_string()).collect();
    let text = format!("name = \"{ZENOH_SERVICE}\"\nargs = [{}]\n", quoted.join(", "));
    Ok(toml::from_str(&text)?)
}

/// Checks the endpoints before anything starts: `tcp/HOST:PORT`, and a listening one free now.
pub fn check_endpoints(listen: &[String], connect: &[String]) -> anyhow::Result<()> {
    for (flag, e) in
        listen.iter().map(|e| ("--zenoh-listen", e)).chain(connect.iter().map(|e| ("--zenoh-connect", e)))
    {
        let addr = harvey_runtime::endpoint::tcp_address(flag, e)?;
        use std::net::ToSocketAddrs;
        let at = addr
            .to_socket_addrs()
            .ok()
            .and_then(|mut a| a.next())
            .ok_or_else(|| anyhow::anyhow!("{flag} {e}: no address found for `{addr}`"))?;
        if flag == "--zenoh-listen" && at.port() != 0 {
            std::net::TcpListener::bind(at)
                .map_err(|err| anyhow::anyhow!("{flag} {e}: cannot listen there: {err}"))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_zenoh_service_exports_everything_on_the_endpoints_given() {
        let s = zenoh_service(&["tcp/127.0.0.1:7447".into()], &["tcp/10.0.0.2:7447".into()], None)
            .expect("service");
        assert_eq!((s.name(), s.binary_name().as_str()), ("zenoh-bridge", "harvey-zenoh-bridge"));
        assert_eq!(
            s.args,
            [
                "--export",
                "all",
                "--zenoh-listen",
                "tcp/127.0.0.1:7447",
                "--zenoh-connect",
                "tcp/10.0.0.2:7447"
            ]
        );
        assert!(s.clock_party);
        let ros = zenoh_service(&["tcp/127.0.0.1:7447".into()], &[], Some(3)).expect("service");
        assert_eq!(ros.args[..4], ["--export", "all", "--ros2-domain", "3"]);
        assert!(check_endpoints(&["tcp/127.0.0.1:0".into()], &[]).is_ok());
        let e = check_endpoints(&["127.0.0.1:7447".into()], &[]).expect_err("no tcp/").to_string();
        assert!(e.contains("--zenoh-listen 127.0.0.1:7447: not `tcp/HOST:PORT`"), "{e}");
        let taken = std::net::TcpListener::bind("127.0.0.1:0").expect("bind");
        let port = taken.local_addr().expect("addr").port();
        let e = check_endpoints(&[format!("tcp/127.0.0.1:{port}")], &[]).expect_err("in use").to_string();
        assert!(e.contains("cannot listen there"), "{e}");
    }
}
