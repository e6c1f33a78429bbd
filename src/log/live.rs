//! The live view (`polhode run --live`): the run served as it computes over the Foxglove
//! WebSocket protocol, version 1 (Foxglove, "Foxglove WebSocket Protocol",
//! <https://github.com/foxglove/ws-protocol/blob/main/docs/spec.md>). The server is one more
//! outlet of the log (the private `log::outlets`): the same topics, schemas, channel metadata and
//! encoded messages as the MCAP file, stamped with the same log times. A run without `--live`
//! creates none of this (no socket, no thread).
//!
//! The protocol's subprotocol is named `foxglove.websocket.v1` by Foxglove Studio and the
//! `@foxglove/ws-protocol` clients, and `foxglove.sdk.v1` by the Foxglove SDK and the current
//! app; the two are the same protocol under two names, and the server accepts either (the
//! `foxglove` crate's own server accepts only the second, which Foxglove Studio does not
//! offer). Only what a viewer of a log needs is served: `serverInfo`, `advertise`,
//! `subscribe`, `unsubscribe`, binary message data (opcode 1) and the `time` capability: the
//! log time of each new sample (opcode 2) before its messages, so that a viewer stamps what it
//! receives with sim time, not with its arrival.
//!
//! A viewer that connects late misses what was sent before it subscribed; the one message
//! sent only once, the Earth of the orbit view (`/earth`), is kept and sent again to each new
//! subscriber. A viewer that falls more than [`BACKLOG`] messages behind loses messages rather
//! than slow the run. [`super::pacing::Pacing`] holds the samples to a multiple of
//! wall-clock time (`--realtime`).

use foxglove::Schema;
use serde_json::json;
use std::collections::{BTreeMap, HashMap};
use std::io::{self, ErrorKind};
use std::net::{TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::sync::{Arc, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};
use tungstenite::Message;
use tungstenite::handshake::server::{ErrorResponse, Request, Response};

/// The port of the live view unless `--port` says otherwise (Foxglove's default for a
/// WebSocket connection).
pub const DEFAULT_PORT: u16 = 8765;

/// The address the server listens on: this machine only (reach it from elsewhere through an
/// SSH tunnel).
pub const HOST: &str = "127.0.0.1";

/// The protocol's two names, the newer preferred when a client offers both.
const SUBPROTOCOLS: [&str; 2] = ["foxglove.sdk.v1", "foxglove.websocket.v1"];

/// Messages queued for one viewer before newer ones are dropped.
pub const BACKLOG: usize = 100_000;

/// How often the server's threads look for work and for the end (a live run only).
const POLL: Duration = Duration::from_millis(10);

/// A running live-view server.
pub struct LiveServer {
    shared: Arc<Shared>,
    port: u16,
    accept: Option<JoinHandle<()>>,
}

/// What the server's threads share.
#[derive(Default)]
struct Shared {
    /// The advertised channels, by id.
    channels: Mutex<BTreeMap<u32, Advertised>>,
    /// The connected viewers.
    clients: Mutex<Vec<Arc<Viewer>>>,
    /// The last message of each latched channel: log time and bytes.
    latched: Mutex<HashMap<u32, (u64, Vec<u8>)>>,
    /// The latest log time published (ns), sent as the clock.
    clock: Mutex<u64>,
    stop: AtomicBool,
}

/// One advertised channel, as the `advertise` operation describes it.
struct Advertised {
    json: serde_json::Value,
}

/// One connected viewer: its subscriptions (channel id → subscription id) and its queue.
struct Viewer {
    subscriptions: Mutex<HashMap<u32, u32>>,
    queue: SyncSender<Message>,
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    // A thread that panicked while holding a lock left plain data behind: carry on.
    m.lock().unwrap_or_else(|e| e.into_inner())
}

impl LiveServer {
    /// Starts the server on [`HOST`]:`port` (`0`: a free port chosen by the system). Fails
    /// when the port cannot be bound (in use, or privileged), saying so.
    pub fn start(port: u16) -> Result<Self, String> {
        let fail = |e: io::Error| format!("cannot serve the live view on {HOST}:{port}: {e}");
        let listener = TcpListener::bind((HOST, port)).map_err(fail)?;
        let port = listener.local_addr().map_err(fail)?.port();
        listener.set_nonblocking(true).map_err(fail)?;
        let shared = Arc::new(Shared::default());
        let accept = {
            let shared = shared.clone();
            std::thread::Builder::new()
                .name("live-view".into())
                .spawn(move || accept_loop(&listener, &shared))
                .map_err(fail)?
        };
        Ok(LiveServer {
            shared,
            port,
            accept: Some(accept),
        })
    }

    /// The port it listens on.
    pub fn port(&self) -> u16 {
        self.port
    }

    /// The address to open in Foxglove (`ws://localhost:<port>`).
    pub fn url(&self) -> String {
        format!("ws://localhost:{}", self.port)
    }

    /// How many viewers are connected.
    pub fn client_count(&self) -> usize {
        lock(&self.shared.clients).len()
    }

    /// Advertises channel `id`, topic `topic`, of messages encoded as `encoding` with
    /// `schema` (binary schemas, such as protobuf's, go base64-encoded, as the protocol says).
    pub(crate) fn advertise(
        &self,
        id: u32,
        topic: &str,
        schema: &Schema,
        encoding: &str,
        metadata: &BTreeMap<String, String>,
    ) {
        let text = match std::str::from_utf8(&schema.data) {
            Ok(t) if schema.encoding != "protobuf" => t.to_string(),
            _ => base64(&schema.data),
        };
        let mut channel = json!({
            "id": id,
            "topic": topic,
            "encoding": encoding,
            "schemaName": schema.name,
            "schema": text,
            "schemaEncoding": schema.encoding,
        });
        if !metadata.is_empty() {
            channel["metadata"] = json!(metadata);
        }
        let message = Message::text(json!({"op": "advertise", "channels": [&channel]}).to_string());
        lock(&self.shared.channels).insert(id, Advertised { json: channel });
        for viewer in lock(&self.shared.clients).iter() {
            let _ = viewer.queue.try_send(message.clone());
        }
    }

    /// Sends message `data` of channel `id`, stamped `log_time` (Unix ns), to the viewers
    /// subscribed to it; `latched`: kept for those that subscribe later.
    pub(crate) fn publish(&self, id: u32, log_time: u64, data: &[u8], latched: bool) {
        if latched {
            lock(&self.shared.latched).insert(id, (log_time, data.to_vec()));
        }
        let tick = {
            let mut clock = lock(&self.shared.clock);
            let later = log_time > *clock;
            *clock = (*clock).max(log_time);
            later
        };
        for viewer in lock(&self.shared.clients).iter() {
            if tick {
                let _ = viewer.queue.try_send(time_frame(log_time));
            }
            let subscription = lock(&viewer.subscriptions).get(&id).copied();
            if let Some(subscription) = subscription {
                let _ = viewer
                    .queue
                    .try_send(message_data(subscription, log_time, data));
            }
        }
    }

    /// Closes the connections and stops the server.
    pub fn stop(mut self) {
        self.shared.stop.store(true, Ordering::SeqCst);
        if let Some(t) = self.accept.take() {
            let _ = t.join();
        }
    }
}

impl Drop for LiveServer {
    fn drop(&mut self) {
        self.shared.stop.store(true, Ordering::SeqCst);
    }
}

/// A binary message-data frame: opcode 1, subscription id, log time, payload.
fn message_data(subscription: u32, log_time: u64, data: &[u8]) -> Message {
    let mut frame = Vec::with_capacity(13 + data.len());
    frame.push(1);
    frame.extend_from_slice(&subscription.to_le_bytes());
    frame.extend_from_slice(&log_time.to_le_bytes());
    frame.extend_from_slice(data);
    Message::binary(frame)
}

/// A binary time frame: opcode 2, the log time (ns) the viewer's clock is at.
fn time_frame(log_time: u64) -> Message {
    let mut frame = Vec::with_capacity(9);
    frame.push(2);
    frame.extend_from_slice(&log_time.to_le_bytes());
    Message::binary(frame)
}

/// Standard base64 with padding (RFC 4648, section 4).
fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[((n >> (18 - 6 * k)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Accepts viewers until the server stops, one thread each.
fn accept_loop(listener: &TcpListener, shared: &Arc<Shared>) {
    let mut viewers = Vec::new();
    while !shared.stop.load(Ordering::SeqCst) {
        match listener.accept() {
            Ok((stream, _)) => {
                let shared = shared.clone();
                if let Ok(t) = std::thread::Builder::new()
                    .name("live-viewer".into())
                    .spawn(move || serve(stream, &shared))
                {
                    viewers.push(t);
                }
            }
            Err(e) if e.kind() == ErrorKind::WouldBlock => std::thread::sleep(POLL),
            Err(_) => std::thread::sleep(POLL),
        }
        viewers.retain(|t: &JoinHandle<()>| !t.is_finished());
    }
    for t in viewers {
        let _ = t.join();
    }
}

/// Serves one viewer: the handshake, then its requests and its queue in turn, until it leaves
/// or the server stops.
fn serve(stream: TcpStream, shared: &Arc<Shared>) {
    if stream.set_nonblocking(false).is_err() || stream.set_read_timeout(Some(POLL)).is_err() {
        return;
    }
    // The refusal is the handshake library's own type, a large value but a rare one.
    #[allow(clippy::result_large_err)]
    let choose = |request: &Request, mut response: Response| {
        let offered: Vec<String> = request
            .headers()
            .get_all("sec-websocket-protocol")
            .iter()
            .filter_map(|h| h.to_str().ok())
            .flat_map(|h| h.split(',').map(|p| p.trim().to_string()))
            .collect();
        match SUBPROTOCOLS
            .iter()
            .find(|p| offered.iter().any(|o| o == *p))
        {
            Some(p) => {
                response
                    .headers_mut()
                    .insert("sec-websocket-protocol", p.parse().expect("a valid header"));
                Ok(response)
            }
            None => {
                let mut refusal = ErrorResponse::new(Some(format!(
                    "expected the subprotocol {} or {}",
                    SUBPROTOCOLS[1], SUBPROTOCOLS[0]
                )));
                *refusal.status_mut() = tungstenite::http::StatusCode::BAD_REQUEST;
                Err(refusal)
            }
        }
    };
    // The handshake may take several reads of POLL each.
    let deadline = Instant::now() + Duration::from_secs(10);
    let mut attempt = tungstenite::accept_hdr(stream, choose);
    let mut ws = loop {
        match attempt {
            Ok(ws) => break ws,
            Err(tungstenite::HandshakeError::Interrupted(mid)) if Instant::now() < deadline => {
                attempt = mid.handshake();
            }
            Err(_) => return,
        }
    };
    let (queue, outgoing) = sync_channel(BACKLOG);
    let viewer = Arc::new(Viewer {
        subscriptions: Mutex::new(HashMap::new()),
        queue,
    });
    let hello = json!({
        "op": "serverInfo",
        "name": format!("polhode {}", env!("CARGO_PKG_VERSION")),
        "capabilities": ["time"],
        "supportedEncodings": [],
        "metadata": {},
        "sessionId": format!("{}", std::process::id()),
    });
    let _ = viewer.queue.try_send(Message::text(hello.to_string()));
    {
        // Advertised under the clients' lock, so that no channel is advertised twice or missed.
        let mut clients = lock(&shared.clients);
        let channels: Vec<serde_json::Value> = lock(&shared.channels)
            .values()
            .map(|c| c.json.clone())
            .collect();
        if !channels.is_empty() {
            let advertise = json!({"op": "advertise", "channels": channels});
            let _ = viewer.queue.try_send(Message::text(advertise.to_string()));
        }
        clients.push(viewer.clone());
    }
    let _ = converse(&mut ws, &viewer, &outgoing, shared);
    lock(&shared.clients).retain(|v| !Arc::ptr_eq(v, &viewer));
    let _ = ws.close(None);
    let _ = ws.flush();
}

/// Reads the viewer's requests and sends its queue until it leaves or the server stops.
fn converse(
    ws: &mut tungstenite::WebSocket<TcpStream>,
    viewer: &Viewer,
    outgoing: &Receiver<Message>,
    shared: &Shared,
) -> tungstenite::Result<()> {
    while !shared.stop.load(Ordering::SeqCst) {
        match ws.read() {
            Ok(Message::Text(text)) => request(text.as_str(), viewer, shared),
            Ok(Message::Close(_)) => return Ok(()),
            Ok(_) => {}
            Err(tungstenite::Error::Io(e))
                if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {}
            Err(e) => return Err(e),
        }
        let mut sent = false;
        while let Ok(message) = outgoing.try_recv() {
            ws.write(message)?;
            sent = true;
        }
        if sent {
            ws.flush()?;
        }
    }
    Ok(())
}

/// Acts on one JSON request of a viewer: `subscribe` and `unsubscribe` (others are ignored).
fn request(text: &str, viewer: &Viewer, shared: &Shared) {
    let Ok(json) = serde_json::from_str::<serde_json::Value>(text) else {
        return;
    };
    let as_u32 = |v: &serde_json::Value| v.as_u64().and_then(|n| u32::try_from(n).ok());
    match json["op"].as_str() {
        Some("subscribe") => {
            for s in json["subscriptions"].as_array().into_iter().flatten() {
                let (Some(id), Some(channel)) = (as_u32(&s["id"]), as_u32(&s["channelId"])) else {
                    continue;
                };
                if !lock(&shared.channels).contains_key(&channel) {
                    continue;
                }
                lock(&viewer.subscriptions).insert(channel, id);
                if let Some((log_time, data)) = lock(&shared.latched).get(&channel) {
                    let _ = viewer.queue.try_send(message_data(id, *log_time, data));
                }
            }
        }
        Some("unsubscribe") => {
            let ids: Vec<u32> = json["subscriptionIds"]
                .as_array()
                .into_iter()
                .flatten()
                .filter_map(as_u32)
                .collect();
            lock(&viewer.subscriptions).retain(|_, id| !ids.contains(id));
        }
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::base64;

    #[test]
    fn base64_matches_rfc_4648_test_vectors() {
        // RFC 4648, section 10.
        for (plain, coded) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(plain.as_bytes()), coded);
        }
    }
}
