//! The link to the flight controller: one serial port (a USB CDC or a UART, or a
//! pseudo-terminal) or one UDP socket, carrying HIL_SENSOR out and the flight controller's
//! MAVLink back. [`Link::open`] gives the sender's end and, for the device-under-test reader
//! ([`crate::dut`]), the receiving end of the same port or socket.
//!
//! - **Serial**: the port is opened once with a 5 ms read timeout and cloned: the clone writes,
//!   the original goes to the reader. The line must carry the scene's rate: [`check_line`].
//! - **UDP**: the socket is bound to `--bind` (default `0.0.0.0:0`, any port) and connected to
//!   `HOST:PORT`, so it sends every frame there, one frame per datagram, and receives only that
//!   peer's datagrams, each handed to the reader as bytes. A port nobody listens on (ICMP
//!   unreachable) is not an error while the flight controller boots: reads time out.

use super::HitlError;
use std::io::{self, Read, Write};
use std::net::{SocketAddr, ToSocketAddrs, UdpSocket};
use std::time::Duration;

/// Bytes on the wire of one HIL_SENSOR in MAVLink 2, at most (10 header, 64 payload, 2 CRC;
/// MAVLink 2 drops the payload's trailing zero bytes: 74 with [`super::message::FIELDS_SENT`]).
pub const HIL_SENSOR_FRAME_BYTES: u64 = 76;
/// Bytes of one HEARTBEAT in MAVLink 2 (10 header, 9 payload, 2 CRC).
pub const HEARTBEAT_FRAME_BYTES: u64 = 21;

/// Where the flight controller is.
#[derive(Clone, Debug, PartialEq)]
pub enum Target {
    /// A serial port at a line rate (a USB CDC port ignores it).
    Serial {
        /// The port's path.
        path: String,
        /// Bits per second.
        baud: u32,
    },
    /// A UDP peer.
    Udp {
        /// `HOST:PORT` to send to.
        remote: String,
        /// The local address to bind.
        bind: String,
    },
}

impl Target {
    /// The port's path or `udp:HOST:PORT`, for `meta.toml` and messages.
    pub fn label(&self) -> String {
        match self {
            Self::Serial { path, .. } => path.clone(),
            Self::Udp { remote, .. } => format!("udp:{remote}"),
        }
    }

    /// The line rate, for `meta.toml` (0 for UDP).
    pub fn baud(&self) -> u32 {
        match self {
            Self::Serial { baud, .. } => *baud,
            Self::Udp { .. } => 0,
        }
    }
}

/// Refuses a scene rate the serial line cannot carry: each second takes `rate` HIL_SENSOR
/// frames and one HEARTBEAT at 10 bits per byte (8N1).
pub fn check_line(rate_hz: f64, baud: u32) -> Result<(), HitlError> {
    let bits = 10.0 * (rate_hz * HIL_SENSOR_FRAME_BYTES as f64 + HEARTBEAT_FRAME_BYTES as f64);
    if bits > f64::from(baud) {
        return Err(HitlError::LineTooSlow {
            rate_hz,
            baud,
            needed: bits.ceil() as u64,
        });
    }
    Ok(())
}

/// What can take the reader's side of the link.
pub trait ReadWrite: Read + Write + Send {}
impl<T: Read + Write + Send> ReadWrite for T {}

/// The two ends of an open link.
pub struct Link {
    /// Where HIL_SENSOR and HEARTBEAT frames are written.
    pub sender: Box<dyn Write + Send>,
    /// What the device-under-test reader reads the replies from.
    pub receiver: Box<dyn ReadWrite>,
}

impl Link {
    /// Opens `target` (see the module docs).
    pub fn open(target: &Target) -> Result<Self, HitlError> {
        match target {
            Target::Serial { path, baud } => open_serial(path, *baud),
            Target::Udp { remote, bind } => open_udp(remote, bind),
        }
    }
}

fn open_serial(path: &str, baud: u32) -> Result<Link, HitlError> {
    let port = crate::dut::open_dut_port(path, baud).map_err(|e| HitlError::Port {
        path: path.to_string(),
        reason: std::error::Error::source(&e).map_or(e.to_string(), |s| s.to_string()),
    })?;
    let sender = port.try_clone_native().map_err(|e| HitlError::Port {
        path: path.to_string(),
        reason: e.to_string(),
    })?;
    Ok(Link {
        sender: Box::new(sender),
        receiver: Box::new(port),
    })
}

fn resolve(what: &'static str, text: &str) -> Result<SocketAddr, HitlError> {
    let bad = |reason: String| HitlError::Address {
        what,
        text: text.to_string(),
        reason,
    };
    let mut addrs = text.to_socket_addrs().map_err(|e| bad(e.to_string()))?;
    addrs
        .next()
        .ok_or_else(|| bad("it resolves to no address".into()))
}

fn open_udp(remote: &str, bind: &str) -> Result<Link, HitlError> {
    let peer = resolve("--udp", remote)?;
    let local = resolve("--bind", bind)?;
    let failed = |reason: io::Error| HitlError::Udp {
        bind: bind.to_string(),
        remote: remote.to_string(),
        reason: reason.to_string(),
    };
    let socket = UdpSocket::bind(local).map_err(failed)?;
    socket.connect(peer).map_err(failed)?;
    socket
        .set_read_timeout(Some(Duration::from_millis(5)))
        .map_err(failed)?;
    let sender = socket.try_clone().map_err(failed)?;
    Ok(Link {
        sender: Box::new(Datagrams(sender)),
        receiver: Box::new(Datagrams(socket)),
    })
}

/// A connected UDP socket as a byte stream: each `write` is one datagram, each `read` one
/// datagram received; a timeout or the peer's ICMP unreachable reads as a timeout.
struct Datagrams(UdpSocket);

impl Read for Datagrams {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        match self.0.recv(buf) {
            Err(e) if e.kind() == io::ErrorKind::ConnectionRefused => {
                Err(io::ErrorKind::TimedOut.into())
            }
            other => other,
        }
    }
}

impl Write for Datagrams {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        match self.0.send(buf) {
            // The peer is not listening yet (an earlier datagram's ICMP unreachable): the
            // datagram is lost, as UDP allows.
            Err(e) if e.kind() == io::ErrorKind::ConnectionRefused => Ok(buf.len()),
            other => other,
        }
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_line_must_carry_the_rate() {
        assert!(check_line(100.0, 115_200).is_ok());
        let e = check_line(1000.0, 115_200).unwrap_err();
        assert!(e.to_string().contains("760210"), "{e}");
    }

    #[test]
    fn bad_addresses_are_named() {
        let e = open_udp("no-port-here", "0.0.0.0:0").err().unwrap();
        assert!(e.to_string().contains("--udp `no-port-here`"), "{e}");
        let e = open_udp("127.0.0.1:14560", "1.2.3.4.5:0").err().unwrap();
        assert!(e.to_string().contains("--bind"), "{e}");
    }
}
