//! Where a robot server listens, and the byte stream to it.

use std::io::{Read, Write};
use std::net::{Shutdown, TcpListener, TcpStream};
use std::os::unix::net::{UnixListener, UnixStream};
use std::path::PathBuf;
use std::str::FromStr;
use std::time::Duration;

/// A robot server's address: `HOST:PORT` or `tcp://HOST:PORT` for TCP, `unix:PATH` for a
/// Unix socket.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum RobotAddress {
    /// A TCP address, `host:port`.
    Tcp(String),
    /// A Unix-domain socket path.
    Unix(PathBuf),
}

/// An address that could not be read.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("robot address {given:?}: {expected}")]
pub struct AddressError {
    /// What was given.
    pub given: String,
    /// What was expected instead.
    pub expected: &'static str,
}

impl FromStr for RobotAddress {
    type Err = AddressError;

    fn from_str(given: &str) -> Result<RobotAddress, AddressError> {
        let error = |expected| AddressError {
            given: given.to_owned(),
            expected,
        };
        if let Some(path) = given.strip_prefix("unix:") {
            let path = path.strip_prefix("//").unwrap_or(path);
            if path.is_empty() {
                return Err(error("expected a socket path after `unix:`"));
            }
            return Ok(RobotAddress::Unix(PathBuf::from(path)));
        }
        let hostport = given.strip_prefix("tcp://").unwrap_or(given);
        let Some((host, port)) = hostport.rsplit_once(':') else {
            return Err(error("expected HOST:PORT, tcp://HOST:PORT or unix:PATH"));
        };
        if host.is_empty() || port.parse::<u16>().is_err() {
            return Err(error("expected HOST:PORT with a port number from 0 to 65535"));
        }
        Ok(RobotAddress::Tcp(hostport.to_owned()))
    }
}

impl std::fmt::Display for RobotAddress {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RobotAddress::Tcp(hostport) => write!(f, "tcp://{hostport}"),
            RobotAddress::Unix(path) => write!(f, "unix:{}", path.display()),
        }
    }
}

impl RobotAddress {
    /// Opens a stream to the server, giving up after `timeout`.
    pub(crate) fn connect(&self, timeout: Duration) -> std::io::Result<Stream> {
        match self {
            RobotAddress::Tcp(hostport) => {
                let mut last = None;
                for addr in std::net::ToSocketAddrs::to_socket_addrs(hostport.as_str())? {
                    match TcpStream::connect_timeout(&addr, timeout) {
                        Ok(stream) => {
                            stream.set_nodelay(true)?;
                            return Ok(Stream::Tcp(stream));
                        }
                        Err(err) => last = Some(err),
                    }
                }
                Err(last.unwrap_or_else(|| std::io::Error::other("the host name resolved to no address")))
            }
            RobotAddress::Unix(path) => Ok(Stream::Unix(UnixStream::connect(path)?)),
        }
    }

    /// Starts listening; a TCP port of 0 takes a free one ([`Listener::address`] tells which).
    pub fn listen(&self) -> std::io::Result<Listener> {
        match self {
            RobotAddress::Tcp(hostport) => Ok(Listener::Tcp(TcpListener::bind(hostport.as_str())?)),
            RobotAddress::Unix(path) => match UnixListener::bind(path) {
                Ok(listener) => Ok(Listener::Unix(listener, path.clone())),
                // A socket file left by a server that is gone (nothing answers on it) is
                // replaced; one a live server holds is not.
                Err(err)
                    if err.kind() == std::io::ErrorKind::AddrInUse && UnixStream::connect(path).is_err() =>
                {
                    std::fs::remove_file(path)?;
                    Ok(Listener::Unix(UnixListener::bind(path)?, path.clone()))
                }
                Err(err) => Err(err),
            },
        }
    }
}

/// A listening robot server socket.
#[derive(Debug)]
pub enum Listener {
    /// TCP.
    Tcp(TcpListener),
    /// Unix socket, with its path.
    Unix(UnixListener, PathBuf),
}

impl Drop for Listener {
    /// A Unix socket's file goes with its listener.
    fn drop(&mut self) {
        if let Listener::Unix(_, path) = self {
            let _ = std::fs::remove_file(path);
        }
    }
}

impl Listener {
    /// The address clients connect to (with the port actually bound).
    pub fn address(&self) -> std::io::Result<RobotAddress> {
        match self {
            Listener::Tcp(listener) => Ok(RobotAddress::Tcp(listener.local_addr()?.to_string())),
            Listener::Unix(_, path) => Ok(RobotAddress::Unix(path.clone())),
        }
    }

    /// Waits for the next client.
    pub(crate) fn accept(&self) -> std::io::Result<Stream> {
        match self {
            Listener::Tcp(listener) => {
                let (stream, _) = listener.accept()?;
                stream.set_nodelay(true)?;
                Ok(Stream::Tcp(stream))
            }
            Listener::Unix(listener, _) => Ok(Stream::Unix(listener.accept()?.0)),
        }
    }
}

/// A connected byte stream, TCP or Unix.
#[derive(Debug)]
pub(crate) enum Stream {
    Tcp(TcpStream),
    Unix(UnixStream),
}

impl Stream {
    pub(crate) fn try_clone(&self) -> std::io::Result<Stream> {
        match self {
            Stream::Tcp(s) => s.try_clone().map(Stream::Tcp),
            Stream::Unix(s) => s.try_clone().map(Stream::Unix),
        }
    }

    /// Closes both directions, waking a thread blocked reading it.
    pub(crate) fn shutdown(&self) {
        let _ = match self {
            Stream::Tcp(s) => s.shutdown(Shutdown::Both),
            Stream::Unix(s) => s.shutdown(Shutdown::Both),
        };
    }
}

impl Read for Stream {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        match self {
            Stream::Tcp(s) => s.read(buf),
            Stream::Unix(s) => s.read(buf),
        }
    }
}

impl Write for Stream {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        match self {
            Stream::Tcp(s) => s.write(buf),
            Stream::Unix(s) => s.write(buf),
        }
    }

    fn flush(&mut self) -> std::io::Result<()> {
        match self {
            Stream::Tcp(s) => s.flush(),
            Stream::Unix(s) => s.flush(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stale_unix_socket_is_replaced_and_a_live_one_kept() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("robot.sock");
        let address = RobotAddress::Unix(path.clone());
        // A socket file nobody listens on any more.
        drop(std::os::unix::net::UnixListener::bind(&path).unwrap());
        assert!(path.exists());
        let live = address.listen().expect("the stale socket is replaced");
        let err = address.listen().expect_err("a live server's socket is kept");
        assert_eq!(err.kind(), std::io::ErrorKind::AddrInUse);
        drop(live);
        assert!(!path.exists(), "the listener removes its socket file");
    }

    #[test]
    fn addresses_read_and_print() {
        assert_eq!(
            "127.0.0.1:7000".parse::<RobotAddress>().unwrap(),
            RobotAddress::Tcp("127.0.0.1:7000".into())
        );
        assert_eq!(
            "tcp://robot.lab:7000"
                .parse::<RobotAddress>()
                .unwrap()
                .to_string(),
            "tcp://robot.lab:7000"
        );
        assert_eq!(
            "unix:/run/robot.sock".parse::<RobotAddress>().unwrap(),
            RobotAddress::Unix("/run/robot.sock".into())
        );
        for bad in ["robot", "host:port", ":7000", "unix:", "host:70000"] {
            let err = bad.parse::<RobotAddress>().unwrap_err();
            assert!(err.to_string().contains("expected"), "{err}");
        }
    }
}
