//! Live view (`coin-log live`, format.md: live): a recording served to Foxglove over its WebSocket protocol
//! while it is simulated, paced against the wall clock (cargo feature `live`). [`LiveServer`] owns the
//! server; [`LiveTap`] is the recorder's [`Tap`](crate::record::Tap), logging every message byte for byte as
//! the file gets it. The server is latched: a viewer that subscribes late is sent each topic's latest
//! messages at once, so that `/tf_static`, the table and the track levels, written rarely, reach it.

mod tap;

pub use tap::{LiveEvent, LiveTap, Pacing};

use foxglove::websocket::{ChannelView, Client, ServerListener};
use foxglove::{ChannelId, Context, PartialMetadata, RawChannel, WebSocketServer};
use std::collections::HashMap;
use std::io::{Seek, SeekFrom, Write};
use std::net::IpAddr;
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::time::Duration;

/// The default port (the Foxglove app's default for a WebSocket connection).
pub const DEFAULT_PORT: u16 = 8765;
/// Messages queued per viewer before the oldest are dropped. The server's default (1024) is a few dozen
/// samples; this is minutes of a default scene at real time and about 20 MB of a slow viewer's queue at
/// most (messages are ≈ 300 bytes).
pub const MESSAGE_BACKLOG: usize = 1 << 16;
/// The longest [`LiveServer::stop`] waits for connections to close: a viewer that reads closes within
/// milliseconds, one that stopped reading never does.
pub const STOP_WAIT: Duration = Duration::from_secs(2);

/// The server could not start.
#[derive(Debug, thiserror::Error)]
pub enum LiveError {
    /// Binding the address failed (port in use, no such interface, no permission).
    #[error("cannot serve on {address}: {source}")]
    Bind {
        /// `host:port` as asked.
        address: String,
        /// The server's error (its source is the I/O error).
        #[source]
        source: foxglove::FoxgloveError,
    },
}

/// A topic's messages of its latest log time (a sample may write a topic more than once), for viewers that
/// subscribe after they were logged.
#[derive(Default)]
struct Latest {
    log_time: u64,
    messages: Vec<Vec<u8>>,
}

impl Latest {
    fn keep(&mut self, log_time: u64, data: &[u8]) {
        if log_time != self.log_time {
            self.log_time = log_time;
            self.messages.clear();
        }
        self.messages.push(data.to_vec());
    }
}

/// The channels by id, each with its latest messages once it has some.
type Channels = HashMap<ChannelId, (Arc<RawChannel>, Option<Latest>)>;

/// Every channel and its latest messages. Logging and re-sending both hold the lock, so a viewer never gets
/// a topic's messages out of time order.
#[derive(Default)]
struct Latch {
    channels: Mutex<Channels>,
}

impl Latch {
    fn lock(&self) -> MutexGuard<'_, Channels> {
        self.channels.lock().unwrap_or_else(PoisonError::into_inner)
    }

    fn add(&self, channel: Arc<RawChannel>) {
        self.lock().insert(channel.id(), (channel, None));
    }

    /// Logs `data` on `channel` to every subscribed viewer and keeps it with the topic's latest messages.
    fn log(&self, channel: &Arc<RawChannel>, log_time: u64, data: &[u8]) {
        let mut channels = self.lock();
        channel.log_with_meta(data, PartialMetadata::with_log_time(log_time));
        if let Some((_, latest)) = channels.get_mut(&channel.id()) {
            latest
                .get_or_insert_with(Latest::default)
                .keep(log_time, data);
        }
    }
}

impl ServerListener for Latch {
    /// A viewer subscribed: it gets the topic's latest messages now, not at the topic's next message
    /// (which for `/tf_static` never comes).
    fn on_subscribe(&self, client: Client, channel: ChannelView) {
        let channels = self.lock();
        if let Some((raw, Some(latest))) = channels.get(&channel.id()) {
            for data in &latest.messages {
                raw.log_with_meta_to_sink(
                    data,
                    PartialMetadata::with_log_time(latest.log_time),
                    client.sink_id(),
                );
            }
        }
    }
}

/// The running WebSocket server with its own channel context (so that two servers in one process do not
/// share channels).
pub struct LiveServer {
    handle: foxglove::WebSocketServerHandle,
    context: Arc<Context>,
    latch: Arc<Latch>,
    host: IpAddr,
}

impl std::fmt::Debug for LiveServer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LiveServer")
            .field("url", &self.url())
            .finish_non_exhaustive()
    }
}

impl LiveServer {
    /// Starts serving on `host:port` (port 0: a free port, see [`Self::port`]), advertising `name` and the
    /// `time` capability (the viewer's clock follows the simulation).
    ///
    /// # Errors
    /// [`LiveError::Bind`] when the address cannot be bound.
    pub fn start(host: IpAddr, port: u16, name: &str) -> Result<Self, LiveError> {
        let context = Context::new();
        let latch = Arc::new(Latch::default());
        let handle = WebSocketServer::new()
            .name(name)
            // The server joins host and port as `host:port`: an IPv6 address needs its brackets.
            .bind(
                match host {
                    IpAddr::V4(v4) => v4.to_string(),
                    IpAddr::V6(v6) => format!("[{v6}]"),
                },
                port,
            )
            .context(&context)
            .capabilities([foxglove::websocket::Capability::Time])
            .supported_encodings(["json", "protobuf"])
            .message_backlog_size(MESSAGE_BACKLOG)
            .listener(latch.clone())
            .start_blocking()
            .map_err(|source| LiveError::Bind {
                address: socket_address(host, port),
                source,
            })?;
        Ok(Self {
            handle,
            context,
            latch,
            host,
        })
    }

    /// The port served (the one picked when started on port 0).
    #[must_use]
    pub fn port(&self) -> u16 {
        self.handle.port()
    }

    /// The URL a viewer connects to: `ws://127.0.0.1:8765`.
    #[must_use]
    pub fn url(&self) -> String {
        format!("ws://{}", socket_address(self.host, self.port()))
    }

    /// Viewers connected now.
    #[must_use]
    pub fn clients(&self) -> usize {
        self.handle.client_count()
    }

    /// Closes every connection and stops serving, waiting at most [`STOP_WAIT`] for the connections to
    /// close.
    pub fn stop(self) {
        let shutdown = self.handle.stop();
        let (closed, wait) = std::sync::mpsc::channel();
        // On a thread of its own so that the wait can end: a viewer that stopped reading keeps its task
        // blocked on a full socket, and `live --exit` never exited (SIGTERM only said "stopping").
        // Whatever is still open closes when the process exits.
        let waiter = std::thread::Builder::new().spawn(move || {
            shutdown.wait_blocking();
            let _ = closed.send(());
        });
        if waiter.is_ok() {
            let _ = wait.recv_timeout(STOP_WAIT);
        }
    }
}

/// `host:port`, with an IPv6 host in brackets.
fn socket_address(host: IpAddr, port: u16) -> String {
    std::net::SocketAddr::new(host, port).to_string()
}

/// A seekable writer that keeps nothing: the recorder's output when `live` records no file.
#[derive(Debug, Default)]
pub struct Discard {
    position: u64,
    len: u64,
}

impl Write for Discard {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.position += buf.len() as u64;
        self.len = self.len.max(self.position);
        Ok(buf.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

impl Seek for Discard {
    fn seek(&mut self, pos: SeekFrom) -> std::io::Result<u64> {
        let target = match pos {
            SeekFrom::Start(p) => Some(p),
            SeekFrom::End(d) => self.len.checked_add_signed(d),
            SeekFrom::Current(d) => self.position.checked_add_signed(d),
        };
        self.position = target.ok_or_else(|| {
            std::io::Error::new(std::io::ErrorKind::InvalidInput, "seek before the start")
        })?;
        Ok(self.position)
    }
}
