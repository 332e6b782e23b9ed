//! `harvey topic list | echo TOPIC | hz TOPIC`: a running domain seen from a terminal, as
//! `ros2 topic` shows a ROS 2 graph; and `harvey iox2-config`, the iceoryx2 configuration under
//! which the `iox2` tools see a domain.

mod hz;
mod source;

use std::time::{Duration, Instant};

use harvey_bus::{Bus, Waiter, Wake};

/// What `echo` and `hz` watch.
#[derive(clap::Args)]
pub struct Watch {
    /// The topic, as `harvey topic list` names it (`sonar/ring`; a leading `/` is dropped).
    topic: String,
    /// The bus domain (the run's `--prefix`).
    #[arg(long, default_value = harvey_bus::DEFAULT_PREFIX)]
    prefix: String,
    /// Stop after this many messages.
    #[arg(long)]
    count: Option<u64>,
    /// One JSON object per line instead of text.
    #[arg(long)]
    json: bool,
    /// How long to wait for the topic to appear in the domain (seconds).
    #[arg(long, default_value_t = 10.0)]
    wait_s: f64,
    /// Give up when no message has come for this long (seconds; default: wait on).
    #[arg(long)]
    timeout_s: Option<f64>,
}

#[derive(clap::Subcommand)]
pub enum TopicCmd {
    /// The topics of a running domain, with their types and the nodes attached to them.
    List {
        #[arg(long, default_value = harvey_bus::DEFAULT_PREFIX)]
        prefix: String,
        #[arg(long)]
        json: bool,
    },
    /// Prints a topic's messages, decoded as the recorder records them.
    Echo(Watch),
    /// Prints a topic's rate of arrival, about once a second.
    Hz {
        #[command(flatten)]
        watch: Watch,
        /// Intervals the rate is averaged over.
        #[arg(long, default_value_t = 100)]
        window: usize,
    },
}

pub fn run(cmd: &TopicCmd) -> anyhow::Result<i32> {
    match cmd {
        TopicCmd::List { prefix, json } => list(prefix, *json),
        TopicCmd::Echo(w) => watch(w, None),
        TopicCmd::Hz { watch: w, window } => watch(w, Some(hz::Rate::new(*window))),
    }
}

/// `harvey iox2-config --prefix P`: prints the domain's iceoryx2 configuration.
pub fn iox2_config(prefix: &str) -> anyhow::Result<i32> {
    print!("{}", harvey_bus::iceoryx2_config(prefix)?);
    Ok(0)
}

fn list(prefix: &str, json: bool) -> anyhow::Result<i32> {
    let topics = harvey_bus::topics(prefix)?;
    if json {
        for t in &topics {
            println!("{}", serde_json::json!({"topic": t.name, "type": t.type_name, "nodes": t.nodes}));
        }
    } else if topics.is_empty() {
        eprintln!("no topics in domain `{prefix}` (is a launch running with --prefix {prefix}?)");
    } else {
        for t in &topics {
            println!("/{:<22} {:<32} {}", t.name, t.type_name, t.nodes.join(", "));
        }
    }
    Ok(0)
}

/// Waits until `name` is a topic of the domain.
fn wait_for_topic(prefix: &str, name: &str, wait: Duration) -> anyhow::Result<()> {
    let until = Instant::now() + wait;
    loop {
        let topics = harvey_bus::topics(prefix)?;
        if topics.iter().any(|t| t.name == name) {
            return Ok(());
        }
        if Instant::now() >= until {
            let there: Vec<&str> = topics.iter().map(|t| t.name.as_str()).collect();
            anyhow::bail!(
                "no topic `{name}` in domain `{prefix}` after {:.1} s (there: {})",
                wait.as_secs_f64(),
                if there.is_empty() { "none".to_owned() } else { there.join(", ") }
            );
        }
        std::thread::sleep(Duration::from_millis(100));
    }
}

fn seconds(s: f64, what: &str) -> anyhow::Result<Duration> {
    Duration::try_from_secs_f64(s).map_err(|_| anyhow::anyhow!("{what}: {s} is not a duration in seconds"))
}

/// `echo` (no rate) or `hz`: takes the topic's messages until `--count`, `--timeout-s` or Ctrl-C.
fn watch(w: &Watch, mut rate: Option<hz::Rate>) -> anyhow::Result<i32> {
    harvey_bus::validate_prefix(&w.prefix)?;
    let name = w.topic.trim_start_matches('/');
    let timeout = w.timeout_s.map(|s| seconds(s, "--timeout-s")).transpose()?;
    wait_for_topic(&w.prefix, name, seconds(w.wait_s, "--wait-s")?)?;
    let bus = Bus::join_with_prefix("harvey-topic", &w.prefix)?;
    let source = source::open(&bus, name)?;
    let waiter = Waiter::new()?;
    let _a = waiter.attach(source.waitable())?;
    let (start, mut printed_at) = (Instant::now(), Instant::now());
    let (mut seen, mut first_batch) = (0u64, rate.is_some());
    let echo = rate.is_none();
    while w.count.is_none_or(|c| seen < c) {
        let tick = if rate.is_some() { Some(Duration::from_secs(1)) } else { timeout };
        match waiter.wait(tick)? {
            Wake::Shutdown => break,
            Wake::Timeout if rate.is_none() => {
                anyhow::bail!("no message on `{name}` for {:?}", tick.unwrap_or_default())
            }
            _ => {}
        }
        let now = start.elapsed();
        source.take(echo, &mut |m| {
            // hz: what comes with the first wake-up is the topic's history, handed over on
            // connecting, not arrivals.
            if first_batch {
                return;
            }
            if w.count.is_some_and(|c| seen >= c) {
                return;
            }
            seen += 1;
            match (&mut rate, m.value) {
                (Some(r), _) => r.arrived(now),
                (None, Some(v)) if w.json => println!("{v}"),
                (None, Some(v)) => println!("{}---", yaml(&v, 0)),
                (None, None) => println!("stamp_ns: {}", m.stamp_ns),
            }
        })?;
        first_batch = false;
        if let Some(r) = &rate {
            let idle = timeout.is_some_and(|t| printed_at.elapsed() >= t && r.stats().is_none());
            anyhow::ensure!(!idle, "no message on `{name}` for {:?}", timeout.unwrap_or_default());
            if printed_at.elapsed() >= Duration::from_secs(1) || w.count.is_some_and(|c| seen >= c) {
                if let Some(s) = r.stats() {
                    println!("{}", if w.json { s.json().to_string() } else { s.text() });
                }
                printed_at = Instant::now();
            }
        }
    }
    Ok(0)
}

/// A decoded message as `ros2 topic echo` prints it: fields one a line, nested ones indented,
/// arrays of numbers on one line.
fn yaml(v: &serde_json::Value, indent: usize) -> String {
    use serde_json::Value;
    let pad = "  ".repeat(indent);
    let mut out = String::new();
    if let Value::Object(fields) = v {
        for (k, f) in fields {
            match f {
                Value::Object(_) => out.push_str(&format!("{pad}{k}:\n{}", yaml(f, indent + 1))),
                Value::Array(items) if items.iter().any(|i| i.is_object()) => {
                    out.push_str(&format!("{pad}{k}:\n"));
                    for i in items {
                        let inner = yaml(i, indent + 2);
                        out.push_str(&format!("{pad}- {}", inner.trim_start()));
                    }
                }
                other => out.push_str(&format!("{pad}{k}: {other}\n")),
            }
        }
    }
    out
}
