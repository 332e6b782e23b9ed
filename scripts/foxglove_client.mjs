// A Foxglove WebSocket client, as a third party would write one, for tests/foxglove.rs and for
// looking at a live run from a terminal: it connects to a Foxglove bridge (`harvey run
// --foxglove`), subscribes to every advertised channel and decodes every message with the
// channel's own `ros2msg` schema (@foxglove/rosmsg + @foxglove/rosmsg2-serialization), as the
// Foxglove app does. Its packages come from scripts/foxglove_setup (Node 18 or newer).
//
//   node scripts/foxglove_client.mjs --modules target/foxglove-node --url ws://127.0.0.1:8765 \
//        [--need TOPIC=N]... [--echo TOPIC]... [--timeout-s S]
//
// Prints JSON lines: {"advertised": {...}} for each channel, {"message": {...}} for each message
// of an --echo topic (decoded, with its CDR bytes in hex), and last {"summary": {...}}: the
// messages received and decoded per topic, decode errors, time messages. Exits 0 once every
// --need topic has decoded N messages (or, without --need, at the timeout), 1 at the timeout
// with a need unmet, 2 when it cannot connect.
import { createRequire } from "node:module";
import path from "node:path";

const args = { modules: "target/foxglove-node", url: "ws://127.0.0.1:8765", need: {}, echo: new Set(), timeoutS: 60 };
const argv = process.argv.slice(2);
for (let i = 0; i < argv.length; i++) {
  const [flag, value] = [argv[i], argv[i + 1]];
  if (value === undefined) throw new Error(`${flag} needs a value`);
  i++;
  if (flag === "--modules") args.modules = value;
  else if (flag === "--url") args.url = value;
  else if (flag === "--timeout-s") args.timeoutS = Number(value);
  else if (flag === "--echo") args.echo.add(value.replace(/^\/?/, "/"));
  else if (flag === "--need") {
    const [topic, n] = value.split("=");
    args.need[topic.replace(/^\/?/, "/")] = Number(n ?? 1);
  } else throw new Error(`unknown option ${flag}`);
}

const require = createRequire(path.resolve(args.modules, "package.json"));
const { FoxgloveClient } = require("@foxglove/ws-protocol");
const { parse } = require("@foxglove/rosmsg");
const { MessageReader } = require("@foxglove/rosmsg2-serialization");
const WebSocket = require("ws");

const out = (obj) =>
  process.stdout.write(
    JSON.stringify(obj, (_, v) => (typeof v === "bigint" ? v.toString() : v)) + "\n",
  );
const hex = (view) => Buffer.from(view.buffer, view.byteOffset, view.byteLength).toString("hex");

// Foxglove's SDK server speaks `foxglove.sdk.v1`: the Foxglove WebSocket protocol whose
// advertisements carry their schemas inline, as ws-protocol's client reads them.
const ws = new WebSocket(args.url, ["foxglove.sdk.v1"]);
const client = new FoxgloveClient({ ws });
const channels = new Map(); // subscription id -> { topic, reader }
const received = {};
const decoded = {};
const errors = [];
let timeMessages = 0;

let finished = false;
function finish(code) {
  if (finished) return;
  finished = true;
  out({ summary: { received, decoded, errors, time_messages: timeMessages, subprotocol: ws.protocol } });
  ws.close();
  // Exit once stdout has drained: a write to a full pipe is queued, and process.exit() would drop
  // it (an echoed camera frame's line is some 600 kB; the reader saw it cut at 64 KiB).
  process.stdout.write("", () => process.exit(code));
}

const needsMet = () =>
  Object.keys(args.need).length > 0 &&
  Object.entries(args.need).every(([topic, n]) => (decoded[topic] ?? 0) >= n);

setTimeout(() => finish(Object.keys(args.need).length > 0 ? 1 : 0), args.timeoutS * 1000);
client.on("error", (e) => {
  errors.push(`socket: ${e.message ?? e}`);
  if (channels.size === 0) finish(2);
});
client.on("close", () => finish(needsMet() ? 0 : 1));
client.on("time", () => timeMessages++);

client.on("advertise", (advertised) => {
  for (const ch of advertised) {
    out({ advertised: { topic: ch.topic, encoding: ch.encoding, schemaName: ch.schemaName, schemaEncoding: ch.schemaEncoding } });
    let reader = null;
    try {
      if (ch.encoding !== "cdr" || ch.schemaEncoding !== "ros2msg") throw new Error(`${ch.encoding}/${ch.schemaEncoding}`);
      reader = new MessageReader(parse(ch.schema, { ros2: true }));
    } catch (e) {
      errors.push(`${ch.topic}: schema ${ch.schemaName} does not parse: ${e.message}`);
    }
    channels.set(client.subscribe(ch.id), { topic: ch.topic, reader });
  }
});

client.on("message", ({ subscriptionId, timestamp, data }) => {
  if (finished) return;
  const ch = channels.get(subscriptionId);
  if (!ch) return;
  received[ch.topic] = (received[ch.topic] ?? 0) + 1;
  if (!ch.reader) return;
  let value;
  try {
    value = ch.reader.readMessage(data);
  } catch (e) {
    errors.push(`${ch.topic}: a message does not decode: ${e.message}`);
    return;
  }
  const stamp = value.header?.stamp;
  if (stamp && BigInt(stamp.sec) * 1000000000n + BigInt(stamp.nanosec) !== timestamp) {
    errors.push(`${ch.topic}: logged at ${timestamp}, stamped ${stamp.sec}.${stamp.nanosec}`);
  }
  decoded[ch.topic] = (decoded[ch.topic] ?? 0) + 1;
  if (args.echo.has(ch.topic)) {
    if (value.data instanceof Uint8Array) {
      // Pixels: their count and sum stand for them.
      const sum = value.data.reduce((s, b) => (s + b) >>> 0, 0);
      value = { ...value, data: { bytes: value.data.length, sum } };
    }
    out({ message: { topic: ch.topic, log_time: timestamp, value, cdr: hex(data) } });
  }
  if (needsMet()) finish(0);
});
