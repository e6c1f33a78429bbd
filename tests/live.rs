//! The live view (`polhode run --live`, docs/viewing.md#live-view): a plain WebSocket client
//! speaking the Foxglove WebSocket protocol (subprotocol `foxglove.websocket.v1`: the server's
//! `advertise`, the client's `subscribe`, binary message-data frames of opcode 1, subscription
//! id and log time in little-endian) subscribes to `/tf` and `/telemetry` of a paced run and
//! checks what arrives: the schemas the MCAP log names, messages that decode (a unit quaternion
//! turning `body` in `world`; |H| held by a run that only dissipates energy), byte for byte the
//! messages of the MCAP written by the same run, the clock (opcode 2) at each message's log
//! time before it, and sim time going no faster than asked.

mod common;

use foxglove::messages::FrameTransforms;
use prost::Message as _;
use std::collections::BTreeMap;
use std::io::{BufRead, BufReader};
use std::net::TcpStream;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};
use tungstenite::Message;
use tungstenite::client::IntoClientRequest;

/// Time allowed for anything to happen before the test gives up.
const PATIENCE: Duration = Duration::from_secs(90);

/// The child process, killed if the test ends before it does.
struct Killed(Child);

impl Drop for Killed {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// A fresh, empty scratch directory for one test, removed when it passes.
fn scratch(name: &str) -> common::Scratch {
    common::Scratch::new("polhode-live", name)
}

/// Starts `polhode run` with `args`; returns it and its stderr lines as they come.
fn spawn(args: &[&str]) -> (Killed, mpsc::Receiver<String>) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_polhode"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let stderr = child.stderr.take().unwrap();
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            if tx.send(line).is_err() {
                break;
            }
        }
    });
    (Killed(child), rx)
}

/// The port in the `live view: ws://localhost:<port>` line of stderr.
fn announced_port(lines: &mpsc::Receiver<String>) -> u16 {
    let deadline = Instant::now() + PATIENCE;
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        let line = lines
            .recv_timeout(left)
            .expect("no `live view: ws://localhost:<port>` line on stderr");
        if let Some(rest) = line.split("ws://localhost:").nth(1) {
            let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
            return digits.parse().unwrap();
        }
    }
}

/// What the client saw of one channel.
#[derive(Default)]
struct Seen {
    schema_name: String,
    encoding: String,
    /// (log time in ns, payload, wall-clock instant of arrival)
    messages: Vec<(u64, Vec<u8>, Instant)>,
    /// For each message, the clock the server had sent before it (ns; 0 if none).
    clock_before: Vec<u64>,
}

/// Connects to the live view on `port`, subscribes to `topics` and collects until each has
/// `count` messages.
fn watch(port: u16, topics: &[&str], count: usize) -> BTreeMap<String, Seen> {
    let stream = TcpStream::connect(("127.0.0.1", port)).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(5)))
        .unwrap();
    let mut request = format!("ws://127.0.0.1:{port}")
        .into_client_request()
        .unwrap();
    request.headers_mut().insert(
        "Sec-WebSocket-Protocol",
        "foxglove.websocket.v1".parse().unwrap(),
    );
    let (mut ws, response) = tungstenite::client(request, stream).unwrap();
    assert_eq!(
        response.headers()["Sec-WebSocket-Protocol"],
        "foxglove.websocket.v1"
    );
    let mut seen: BTreeMap<String, Seen> = BTreeMap::new();
    // Subscription id → topic.
    let mut subscribed: BTreeMap<u32, String> = BTreeMap::new();
    // The server's clock (the `time` capability: binary opcode 2).
    let mut clock = 0u64;
    let deadline = Instant::now() + PATIENCE;
    while topics
        .iter()
        .any(|t| seen.get(*t).is_none_or(|s| s.messages.len() < count))
    {
        assert!(
            Instant::now() < deadline,
            "timed out; seen {:?}",
            seen.iter()
                .map(|(t, s)| (t, s.messages.len()))
                .collect::<Vec<_>>()
        );
        let message = match ws.read() {
            Ok(m) => m,
            Err(tungstenite::Error::Io(e))
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) =>
            {
                continue;
            }
            Err(e) => panic!("the live view's connection failed: {e}"),
        };
        match message {
            Message::Text(text) => {
                let json: serde_json::Value = serde_json::from_str(text.as_str()).unwrap();
                if json["op"] != "advertise" {
                    continue;
                }
                let mut subscriptions = Vec::new();
                for channel in json["channels"].as_array().unwrap() {
                    let topic = channel["topic"].as_str().unwrap();
                    if !topics.contains(&topic) || seen.contains_key(topic) {
                        continue;
                    }
                    let id = subscribed.len() as u32 + 1;
                    subscribed.insert(id, topic.to_string());
                    seen.insert(
                        topic.to_string(),
                        Seen {
                            schema_name: channel["schemaName"].as_str().unwrap().to_string(),
                            encoding: channel["encoding"].as_str().unwrap().to_string(),
                            messages: Vec::new(),
                            clock_before: Vec::new(),
                        },
                    );
                    subscriptions.push(serde_json::json!({"id": id, "channelId": channel["id"]}));
                }
                if !subscriptions.is_empty() {
                    let subscribe =
                        serde_json::json!({"op": "subscribe", "subscriptions": subscriptions});
                    ws.send(Message::Text(subscribe.to_string().into()))
                        .unwrap();
                }
            }
            Message::Binary(frame) => {
                // Opcode 2: time; opcode 1: message data.
                if frame.first() == Some(&2) {
                    let time = u64::from_le_bytes(frame[1..9].try_into().unwrap());
                    assert!(time >= clock, "the clock went back from {clock} to {time}");
                    clock = time;
                    continue;
                }
                if frame.first() != Some(&1) {
                    continue;
                }
                let id = u32::from_le_bytes(frame[1..5].try_into().unwrap());
                let log_time = u64::from_le_bytes(frame[5..13].try_into().unwrap());
                let topic = &subscribed[&id];
                let s = seen.get_mut(topic).unwrap();
                s.messages
                    .push((log_time, frame[13..].to_vec(), Instant::now()));
                s.clock_before.push(clock);
            }
            _ => {}
        }
    }
    let _ = ws.close(None);
    seen
}

/// The doubles of a proto3 message of doubles, by field number (absent fields are 0).
fn doubles(mut bytes: &[u8]) -> BTreeMap<u64, f64> {
    let mut fields = BTreeMap::new();
    while !bytes.is_empty() {
        let key = prost::encoding::decode_varint(&mut bytes).unwrap();
        assert_eq!(key & 7, 1, "a field that is not a double (wire type 1)");
        let (value, rest) = bytes.split_at(8);
        fields.insert(key >> 3, f64::from_le_bytes(value.try_into().unwrap()));
        bytes = rest;
    }
    fields
}

/// The messages of `topic` in the MCAP at `path`, by log time.
fn mcap_messages(path: &Path, topic: &str) -> BTreeMap<u64, Vec<u8>> {
    let bytes = std::fs::read(path).unwrap();
    mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(Result::unwrap)
        .filter(|m| m.channel.topic == topic)
        .map(|m| (m.log_time, m.data.into_owned()))
        .collect()
}

#[test]
fn a_client_receives_tf_and_telemetry_as_the_run_computes() {
    let dir = scratch("watch");
    let mcap = dir.join("live.mcap");
    // 40 s of sim time at 8 times wall-clock time: 5 s, 5 samples per sim second.
    let speed = 8.0;
    let (mut child, lines) = spawn(&[
        "run",
        "scenarios/explorer1.yaml",
        "--duration",
        "40",
        "--out",
        mcap.to_str().unwrap(),
        "--live",
        "--port",
        "0",
        "--realtime",
        "8",
        "--live-linger",
        "0",
    ]);
    let port = announced_port(&lines);
    let seen = watch(port, &["/tf", "/telemetry"], 40);

    let tf = &seen["/tf"];
    let telemetry = &seen["/telemetry"];
    // Each sample's time comes before its messages, so a viewer stamps them with sim time.
    for s in [tf, telemetry] {
        for ((log_time, _, _), clock) in s.messages.iter().zip(&s.clock_before) {
            assert_eq!(
                clock, log_time,
                "message at {log_time} after the clock {clock}"
            );
        }
    }
    // The schema names of docs/logs.md, as in the MCAP.
    assert_eq!(tf.schema_name, "foxglove.FrameTransforms");
    assert_eq!(telemetry.schema_name, "polhode.Telemetry");
    assert_eq!(
        (tf.encoding.as_str(), telemetry.encoding.as_str()),
        ("protobuf", "protobuf")
    );

    for (_, payload, _) in &tf.messages {
        let transforms = FrameTransforms::decode(payload.as_slice()).unwrap();
        let body = &transforms.transforms[0];
        assert_eq!(
            (body.parent_frame_id.as_str(), body.child_frame_id.as_str()),
            ("world", "body")
        );
        let q = body.rotation.as_ref().unwrap();
        let norm = (q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w).sqrt();
        assert!((norm - 1.0).abs() < 1e-9, "|q| = {norm}");
    }
    // Field 1 is sim_time, 15 h_norm (docs/logs.md): energy goes, angular momentum stays.
    let samples: Vec<BTreeMap<u64, f64>> = telemetry
        .messages
        .iter()
        .map(|(_, p, _)| doubles(p))
        .collect();
    let h0 = samples[0][&15];
    assert!(h0 > 0.0);
    for s in &samples {
        assert!(
            (s[&15] / h0 - 1.0).abs() < 1e-6,
            "|H| {} against {h0}",
            s[&15]
        );
    }
    let times: Vec<f64> = samples
        .iter()
        .map(|s| s.get(&1).copied().unwrap_or(0.0))
        .collect();
    assert!(
        times.windows(2).all(|w| w[1] > w[0]),
        "sim time not increasing: {times:?}"
    );

    // Paced: the sim time received cannot have advanced faster than `speed` times the wall
    // clock (50 ms allowed for the frames' own delivery).
    let first = &telemetry.messages[0];
    let last = telemetry.messages.last().unwrap();
    let sim_span = times.last().unwrap() - times[0];
    let wall_span = last.2.duration_since(first.2).as_secs_f64();
    assert!(sim_span > 5.0, "sim span {sim_span} s");
    assert!(
        wall_span >= sim_span / speed - 0.05,
        "{sim_span} s of sim time arrived in {wall_span} s of wall-clock time"
    );

    // The run ends by itself (--live-linger 0), then its MCAP holds the same messages.
    let deadline = Instant::now() + PATIENCE;
    let status = loop {
        if let Some(status) = child.0.try_wait().unwrap() {
            break status;
        }
        assert!(Instant::now() < deadline, "the run did not end");
        std::thread::sleep(Duration::from_millis(50));
    };
    assert!(status.success(), "{status}");
    for (topic, s) in [("/tf", tf), ("/telemetry", telemetry)] {
        let file = mcap_messages(&mcap, topic);
        assert_eq!(file.len(), 201, "{topic}: 40 s at 5 Hz, both ends");
        for (log_time, payload, _) in &s.messages {
            assert_eq!(
                file.get(log_time),
                Some(payload),
                "{topic} at {log_time}: the live message differs from the log's"
            );
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_port_in_use_stops_the_run_before_anything_is_written() {
    let dir = scratch("busy");
    let taken = std::net::TcpListener::bind(("127.0.0.1", 0)).unwrap();
    let port = taken.local_addr().unwrap().port().to_string();
    let out = dir.join("never.mcap");
    let summary = dir.join("never.json");
    let output = Command::new(env!("CARGO_BIN_EXE_polhode"))
        .args([
            "run",
            "scenarios/explorer1.yaml",
            "--duration",
            "1",
            "--live",
            "--port",
        ])
        .arg(&port)
        .arg("--out")
        .arg(&out)
        .arg("--summary")
        .arg(&summary)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("cannot serve the live view") && stderr.contains(&port),
        "{stderr}"
    );
    let left: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
    assert!(left.is_empty(), "files written: {left:?}");
    drop(taken);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn live_options_are_checked() {
    for (args, expected) in [
        (&["--realtime", "0"][..], "--realtime"),
        (&["--realtime=-2"][..], "--realtime"),
        (&["--live-linger", "nan"][..], "--live-linger"),
    ] {
        let output = Command::new(env!("CARGO_BIN_EXE_polhode"))
            .args([
                "run",
                "scenarios/explorer1.yaml",
                "--no-log",
                "--live",
                "--port",
                "0",
            ])
            .args(args)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
    }
    // Pacing and the port mean nothing without a live view.
    let output = Command::new(env!("CARGO_BIN_EXE_polhode"))
        .args([
            "run",
            "scenarios/explorer1.yaml",
            "--no-log",
            "--realtime",
            "2",
        ])
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(2));
}
