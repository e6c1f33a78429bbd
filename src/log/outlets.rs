//! Where a log's messages go: the MCAP file, the live view's server, or both. Each channel is
//! registered once here and gets one id; every message is encoded once and handed to each
//! outlet with the same log time, so the file and the live view carry the same topics,
//! schemas, metadata and bytes.

use super::io_err;
use super::live::LiveServer;
use foxglove::Schema;
use mcap::records::MessageHeader;
use std::collections::BTreeMap;
use std::fs::File;
use std::io::{self, BufWriter};
use std::sync::Arc;

/// The MCAP writer of a log file.
pub(crate) type FileWriter = mcap::Writer<BufWriter<File>>;

/// The outlets of one log and its channels.
pub(crate) struct Outlets {
    file: Option<FileWriter>,
    live: Option<Arc<LiveServer>>,
    /// By channel id: the channel's id in the file, its channel on the server, and whether
    /// its last message is kept for late viewers.
    routes: Vec<Route>,
}

struct Route {
    file: Option<u16>,
    /// Whether the live view has the channel (under the same id as here).
    live: bool,
    latched: bool,
}

impl Outlets {
    /// Outlets writing to `file`, serving on `live`, or both.
    pub(crate) fn new(file: Option<FileWriter>, live: Option<Arc<LiveServer>>) -> Self {
        Outlets {
            file,
            live,
            routes: Vec::new(),
        }
    }

    /// Registers channel `topic` (messages in `encoding`, with `schema` and `metadata`) in
    /// every outlet; returns its id. `latched`: its last message is sent again to each viewer
    /// that subscribes later (the live view; a file keeps everything anyway).
    pub(crate) fn add_channel(
        &mut self,
        topic: &str,
        schema: &Schema,
        encoding: &str,
        metadata: &BTreeMap<String, String>,
        latched: bool,
    ) -> io::Result<u16> {
        let file = match self.file.as_mut() {
            Some(w) => {
                // The writer keeps one copy of identical schemas.
                let schema_id = w
                    .add_schema(&schema.name, &schema.encoding, &schema.data)
                    .map_err(io_err)?;
                Some(
                    w.add_channel(schema_id, topic, encoding, metadata)
                        .map_err(io_err)?,
                )
            }
            None => None,
        };
        let id = u16::try_from(self.routes.len())
            .map_err(|_| io::Error::other("more than 65536 channels in one log"))?;
        let live = match &self.live {
            Some(server) => {
                server.advertise(u32::from(id), topic, schema, encoding, metadata);
                true
            }
            None => false,
        };
        self.routes.push(Route {
            file,
            live,
            latched,
        });
        Ok(id)
    }

    /// Writes one encoded message to `channel` at `log_time` (Unix ns).
    pub(crate) fn write(
        &mut self,
        channel: u16,
        sequence: u32,
        log_time: u64,
        data: &[u8],
    ) -> io::Result<()> {
        let route = &self.routes[usize::from(channel)];
        if let (Some(w), Some(id)) = (self.file.as_mut(), route.file) {
            let header = MessageHeader {
                channel_id: id,
                sequence,
                log_time,
                publish_time: log_time,
            };
            w.write_to_known_channel(&header, data).map_err(io_err)?;
        }
        if let (Some(server), true) = (&self.live, route.live) {
            server.publish(u32::from(channel), log_time, data, route.latched);
        }
        Ok(())
    }

    /// The file's writer, if the log has a file.
    pub(crate) fn file_mut(&mut self) -> Option<&mut FileWriter> {
        self.file.as_mut()
    }

    /// The file's writer, giving up the other outlets.
    pub(crate) fn into_file(self) -> Option<FileWriter> {
        self.file
    }
}
