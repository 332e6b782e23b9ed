//! A Zenoh endpoint as Harvey accepts it, `tcp/HOST:PORT`: checked alike by `harvey` before a
//! launch starts and by the Zenoh bridge when it is started on its own.

/// The `HOST:PORT` of a Zenoh endpoint Harvey accepts, `tcp/HOST:PORT` with Zenoh's optional
/// `#` metadata after it (this build speaks Zenoh over TCP only); the error names `flag` and the
/// endpoint. The host is not resolved here.
pub fn tcp_address<'a>(flag: &str, endpoint: &'a str) -> anyhow::Result<&'a str> {
    let Some(rest) = endpoint.strip_prefix("tcp/") else {
        anyhow::bail!("{flag} {endpoint}: not `tcp/HOST:PORT` (this build speaks Zenoh over TCP only)");
    };
    let addr = rest.split('#').next().unwrap_or(rest);
    let port_ok =
        addr.rsplit_once(':').is_some_and(|(host, port)| !host.is_empty() && port.parse::<u16>().is_ok());
    anyhow::ensure!(port_ok, "{flag} {endpoint}: not `tcp/HOST:PORT`");
    Ok(addr)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]
    use super::*;

    #[test]
    fn endpoints_are_tcp_host_port() {
        assert_eq!(tcp_address("--zenoh-listen", "tcp/127.0.0.1:7447").unwrap(), "127.0.0.1:7447");
        assert_eq!(tcp_address("--zenoh-listen", "tcp/[::1]:7447#iface=lo").unwrap(), "[::1]:7447");
        let e = tcp_address("--zenoh-listen", "udp/127.0.0.1:7447").expect_err("udp").to_string();
        assert!(e.contains("--zenoh-listen udp/127.0.0.1:7447") && e.contains("TCP only"), "{e}");
        assert!(tcp_address("--zenoh-connect", "tcp/127.0.0.1").is_err());
        assert!(tcp_address("--zenoh-connect", "tcp/:7447").is_err());
        assert!(tcp_address("--zenoh-connect", "tcp/host:70000").is_err());
    }
}
