//! The bridge's Zenoh session: a peer that listens on and connects to exactly the endpoints it
//! is given, with multicast scouting and gossip off, so that nothing is opened unless asked and
//! no other host is found unless named.

use zenoh::{Config, Session, Wait};

/// Where the session listens and whom it connects to.
#[derive(Debug, Clone, Default)]
pub struct Endpoints {
    pub listen: Vec<String>,
    pub connect: Vec<String>,
}

/// The session's configuration: peer mode, scouting off, the endpoints given, failing at once
/// when a listening endpoint cannot be bound.
pub fn config(ends: &Endpoints) -> anyhow::Result<Config> {
    for e in &ends.listen {
        harvey_runtime::endpoint::tcp_address("--zenoh-listen", e)?;
    }
    for e in &ends.connect {
        harvey_runtime::endpoint::tcp_address("--zenoh-connect", e)?;
    }
    let mut c = Config::default();
    let json = |v: &[String]| {
        let quoted: Vec<String> = v.iter().map(|e| format!("\"{}\"", e.replace('"', ""))).collect();
        format!("[{}]", quoted.join(","))
    };
    let settings = [
        ("mode", "\"peer\"".to_owned()),
        ("scouting/multicast/enabled", "false".to_owned()),
        ("scouting/gossip/enabled", "false".to_owned()),
        // No admin space, no timestamps: nothing but what the bridge declares.
        ("adminspace/enabled", "false".to_owned()),
        ("listen/endpoints", json(&ends.listen)),
        ("listen/exit_on_failure", "true".to_owned()),
        ("connect/endpoints", json(&ends.connect)),
        // A peer that is not up yet is retried; the session opens regardless, and the bridge
        // waits for the topics it imports, naming them.
        ("connect/exit_on_failure", "false".to_owned()),
    ];
    for (key, value) in settings {
        c.insert_json5(key, &value).map_err(|e| anyhow::anyhow!("Zenoh setting {key} = {value}: {e}"))?;
    }
    Ok(c)
}

/// Opens the session; an endpoint that cannot be bound is an error naming it.
pub fn open(ends: &Endpoints) -> anyhow::Result<Session> {
    anyhow::ensure!(
        !ends.listen.is_empty() || !ends.connect.is_empty(),
        "no Zenoh endpoint: give --zenoh-listen tcp/HOST:PORT or --zenoh-connect tcp/HOST:PORT"
    );
    let c = config(ends)?;
    zenoh::open(c).wait().map_err(|e| {
        anyhow::anyhow!(
            "cannot open the Zenoh session (listen {:?}, connect {:?}): {e}",
            ends.listen,
            ends.connect
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn endpoints_are_checked_before_the_session_opens() {
        let e = open(&Endpoints::default()).expect_err("nothing").to_string();
        assert!(e.contains("no Zenoh endpoint"), "{e}");
        let udp = Endpoints { listen: vec!["udp/127.0.0.1:7447".into()], connect: vec![] };
        let e = open(&udp).expect_err("udp").to_string();
        assert!(e.contains("--zenoh-listen udp/127.0.0.1:7447") && e.contains("TCP only"), "{e}");
    }

    #[test]
    fn a_port_in_use_is_named() {
        let taken = std::net::TcpListener::bind("127.0.0.1:0").expect("bind");
        let port = taken.local_addr().expect("addr").port();
        let ends = Endpoints { listen: vec![format!("tcp/127.0.0.1:{port}")], connect: vec![] };
        let Err(e) = open(&ends) else { panic!("port {port} is in use: the session must not open") };
        let e = e.to_string();
        assert!(e.contains(&format!("tcp/127.0.0.1:{port}")), "{e}");
    }
}
