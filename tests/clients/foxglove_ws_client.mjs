// A Foxglove WebSocket client built only from Foxglove's own libraries, as Lichtblick and other viewers are:
// @foxglove/ws-protocol's FoxgloveClient (it offers the subprotocol "foxglove.websocket.v1"), the `ws`
// WebSocket, and @foxglove/rosmsg + @foxglove/rosmsg2-serialization to decode CDR with the advertised schema.
//
//   node foxglove_ws_client.mjs ws://127.0.0.1:PORT TOPIC COUNT
//
// Subscribes to TOPIC, decodes COUNT messages, and prints one JSON line: the server's name and capabilities,
// the subprotocol agreed, the sim times the server sent (`time` ops) and, per message, its log time and a
// summary of the decoded message (for a LaserScan: frame_id and the number of ranges).
import wsProtocol from "@foxglove/ws-protocol";
import rosmsg from "@foxglove/rosmsg";
import serialization from "@foxglove/rosmsg2-serialization";
import WebSocket from "ws";

const { FoxgloveClient } = wsProtocol; // (CommonJS packages: their exports through the default one)
const { parse } = rosmsg;
const { MessageReader } = serialization;

const [url, topic, countArg] = process.argv.slice(2);
const count = Number(countArg ?? 3);
const ws = new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
const client = new FoxgloveClient({ ws });
const out = { protocol: null, server: null, capabilities: [], times: [], messages: [] };
let reader = null;
let subscription = null;

let finished = false;
const finish = (code) => {
  if (finished) return; // (closing the client below may emit its "close")
  finished = true;
  process.stdout.write(JSON.stringify(out) + "\n");
  client.close();
  process.exit(code);
};
setTimeout(() => finish(2), 60_000).unref();

client.on("open", () => { out.protocol = ws.protocol; });
client.on("error", (e) => { out.error = String(e?.message ?? e); finish(3); });
// closed before COUNT messages (by the server, or the run ending): said, not a silent exit 0 with no output
client.on("close", (e) => { out.closed = { code: e?.code ?? null, reason: String(e?.reason ?? "") }; finish(4); });
client.on("serverInfo", (info) => { out.server = info.name; out.capabilities = info.capabilities; });
client.on("time", (t) => { if (out.times.length < 1000) out.times.push(t.timestamp.toString()); });
client.on("advertise", (channels) => {
  const ch = channels.find((c) => c.topic === topic);
  if (ch === undefined || subscription !== null) return;
  out.channel = { encoding: ch.encoding, schemaName: ch.schemaName, schemaEncoding: ch.schemaEncoding };
  reader = new MessageReader(parse(ch.schema, { ros2: true }));
  subscription = client.subscribe(ch.id);
});
client.on("message", ({ timestamp, data }) => {
  const msg = reader.readMessage(new Uint8Array(data.buffer, data.byteOffset, data.byteLength));
  out.messages.push({
    log_time: timestamp.toString(),
    frame_id: msg.header?.frame_id ?? null,
    ranges: Array.isArray(msg.ranges) || ArrayBuffer.isView(msg.ranges) ? msg.ranges.length : null,
  });
  if (out.messages.length >= count && out.times.length >= 2) finish(0);
});
