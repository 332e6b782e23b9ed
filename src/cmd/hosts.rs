//! `--host NAME`: one host's share of a launch split over two hosts (`host = "NAME"` on a
//! `[[service]]`, `docs/zenoh.md`). The main host (`main`: the clock master's, and every
//! unplaced service's) runs its services with the Zenoh bridge standing in, at their place in
//! the clock chain, for the other host's; the other host runs its services with the bridge as
//! their clock master. The two bridges carry each tick's messages both ways, so the mission
//! records what it records on one host. In real time (`--realtime` on both) there are no turns:
//! each bridge sends what its host's services publish as it comes.

use std::collections::BTreeSet;

use harvey_supervisor::config::{MAIN_HOST, Service};
use harvey_supervisor::{ClockMode, LaunchFile};

use super::zenoh::ZENOH_SERVICE;

/// The bridge of a split launch, as a service.
/// It waits for the other host a second less than the launch waits for it to be ready, so that
/// what it names is said first.
fn bridge(
    role: &str,
    host: &str,
    peer: &str,
    (listen, connect): (&[String], &[String]),
    lf: &LaunchFile,
) -> anyhow::Result<Service> {
    let wait_s = (lf.settings.ready_timeout_ms / 1000).saturating_sub(1).max(1).to_string();
    let mut args = vec!["--chain", role, "--host", host, "--peer-host", peer, "--wait-s", &wait_s];
    for e in listen {
        args.extend(["--zenoh-listen", e]);
    }
    for e in connect {
        args.extend(["--zenoh-connect", e]);
    }
    let quoted: Vec<String> =
        args.into_iter().map(|a| toml::Value::String(a.to_owned()).to_string()).collect();
    Ok(toml::from_str(&format!("name = \"{ZENOH_SERVICE}\"\nargs = [{}]\n", quoted.join(", ")))?)
}

/// Keeps `lf`'s services that run on `host`, with the bridge to the other host.
pub fn place(lf: &mut LaunchFile, host: &str, listen: &[String], connect: &[String]) -> anyhow::Result<()> {
    let file = lf.path.display().to_string();
    let hosts: BTreeSet<&str> =
        std::iter::once(MAIN_HOST).chain(lf.services.iter().map(Service::host)).collect();
    anyhow::ensure!(
        hosts.contains(host),
        "--host {host}: {file} places services on {hosts:?}, none on `{host}`"
    );
    anyhow::ensure!(
        !listen.is_empty() || !connect.is_empty(),
        "--host {host}: the hosts meet over Zenoh: give --zenoh-listen or --zenoh-connect"
    );
    let others: Vec<&str> = hosts.iter().copied().filter(|h| *h != MAIN_HOST).collect();
    let [other] = others[..] else {
        anyhow::bail!(
            "{file} places services on {others:?} besides `{MAIN_HOST}`: a launch splits over two hosts so far"
        );
    };
    let other = other.to_owned();
    let placed: Vec<usize> = (0..lf.services.len()).filter(|&i| lf.services[i].host() == other).collect();
    let (first, last) = (placed[0], placed[placed.len() - 1]);
    anyhow::ensure!(
        last - first + 1 == placed.len(),
        "{file}: the services on `{other}` must follow one another in the file (they take their turns together)"
    );
    for s in &lf.services[first..=last] {
        anyhow::ensure!(
            s.clock_party,
            "{file}: `{}` on `{other}` is no clock party: only parties run away from the main host",
            s.name()
        );
        let named = |n: &Option<toml::Spanned<String>>| n.as_ref().is_some_and(|m| m.get_ref() == s.name());
        anyhow::ensure!(
            !named(&lf.settings.clock_master) && !named(&lf.settings.end_with),
            "{file}: `{}` is the clock master or ends the launch: it runs on `{MAIN_HOST}`",
            s.name()
        );
    }
    if host == MAIN_HOST {
        let b = bridge("stand-in", MAIN_HOST, &other, (listen, connect), lf)?;
        lf.services.drain(first..=last);
        lf.services.insert(first, b);
    } else {
        let b = bridge("segment", &other, MAIN_HOST, (listen, connect), lf)?;
        let mut mine: Vec<Service> = lf.services.drain(first..=last).collect();
        mine.insert(0, b);
        lf.services = mine;
        let named = toml::Spanned::new(0..0, ZENOH_SERVICE.to_owned());
        if lf.settings.clock == ClockMode::Lockstep {
            lf.settings.clock_master = Some(named.clone());
        }
        lf.settings.end_with = Some(named);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn launch(text: &str) -> LaunchFile {
        static N: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
        let n = N.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let dir = std::env::temp_dir().join(format!("harvey-hosts-{}-{n}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("dir");
        let path = dir.join("split.toml");
        std::fs::write(&path, text).expect("write");
        let lf = LaunchFile::load(&path).expect("loads");
        std::fs::remove_dir_all(&dir).ok();
        lf
    }

    const SPLIT: &str = "[launch]\nname = \"s\"\nclock = \"lockstep\"\nclock_master = \"a\"\nend_with = \"d\"\n\n\
        [[service]]\nname = \"a\"\n\n[[service]]\nname = \"b\"\nhost = \"gpu\"\n\n[[service]]\nname = \"c\"\nhost = \"gpu\"\n\n\
        [[service]]\nname = \"d\"\n";
    const EP: &[String] = &[];

    #[test]
    fn each_host_gets_its_share_and_the_bridge_in_the_others_place() {
        let listen = ["tcp/127.0.0.1:7447".to_owned()];
        let mut main = launch(SPLIT);
        place(&mut main, "main", &listen, EP).expect("main");
        let names: Vec<&str> = main.services.iter().map(Service::name).collect();
        assert_eq!(names, ["a", "zenoh-bridge", "d"]);
        assert_eq!(main.clock_chain(), ["a", "zenoh-bridge", "d"]);
        assert_eq!(
            main.services[1].args[..6],
            ["--chain", "stand-in", "--host", "main", "--peer-host", "gpu"]
        );
        let mut gpu = launch(SPLIT);
        place(&mut gpu, "gpu", EP, &listen).expect("gpu");
        assert_eq!(gpu.clock_chain(), ["zenoh-bridge", "b", "c"]);
        assert_eq!(gpu.settings.end_with.as_ref().map(|e| e.get_ref().as_str()), Some("zenoh-bridge"));
        assert_eq!(gpu.services[0].args[..2], ["--chain", "segment"]);
    }

    #[test]
    fn impossible_placements_are_refused_naming_why() {
        let e = |text: &str, host: &str| {
            place(&mut launch(text), host, &["tcp/127.0.0.1:1".into()], EP).expect_err("refused").to_string()
        };
        assert!(e(SPLIT, "cpu").contains("none on `cpu`"), "{}", e(SPLIT, "cpu"));
        let apart = SPLIT
            .replace("name = \"c\"\nhost = \"gpu\"", "name = \"c\"")
            .replace("name = \"d\"\n", "name = \"d\"\nhost = \"gpu\"\n");
        let apart = apart.replace("end_with = \"d\"", "end_with = \"a\"");
        assert!(e(&apart, "main").contains("must follow one another"), "{}", e(&apart, "main"));
        let ends = SPLIT.replace("end_with = \"d\"", "end_with = \"b\"");
        assert!(
            e(&ends, "gpu").contains("`b` is the clock master or ends the launch"),
            "{}",
            e(&ends, "gpu")
        );
        let three = SPLIT
            .replace("name = \"d\"\n", "name = \"d\"\nhost = \"arm\"\n")
            .replace("end_with = \"d\"", "end_with = \"a\"");
        assert!(e(&three, "main").contains("splits over two hosts"), "{}", e(&three, "main"));
        let no_endpoint = place(&mut launch(SPLIT), "main", EP, EP).expect_err("no endpoint").to_string();
        assert!(no_endpoint.contains("give --zenoh-listen or --zenoh-connect"), "{no_endpoint}");
    }
}
