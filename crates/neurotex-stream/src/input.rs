//! Where a live stream's bytes come from: standard input (`-`), a file, a TCP connection
//! (`tcp://ADDRESS`, one client accepted) or UDP datagrams (`udp://ADDRESS`, joined into
//! one byte stream in arrival order).

use std::io::{BufRead, BufReader, Read};
use std::net::{TcpListener, UdpSocket};
use std::path::Path;

use crate::error::DataError;
use crate::Error;

/// Opens `input` for reading; `say` hears what a person waiting on a socket should know
/// (the address listened on, the peer that connected).
///
/// # Errors
/// A file that cannot be opened, an address that cannot be bound, a failed accept; each
/// names the input.
pub fn open(input: &str, say: &dyn Fn(&str)) -> Result<Box<dyn BufRead>, Error> {
    let failed = |what: &str, e: std::io::Error| {
        Error::from(DataError::io(
            Path::new(input),
            std::io::Error::new(e.kind(), format!("{what}: {e}")),
        ))
    };
    if input == "-" {
        return Ok(Box::new(BufReader::new(std::io::stdin())));
    }
    if let Some(address) = input.strip_prefix("tcp://") {
        let listener = TcpListener::bind(address).map_err(|e| failed("listening", e))?;
        let local = listener.local_addr().map_err(|e| failed("listening", e))?;
        say(&format!("listening on tcp://{local}"));
        let (socket, peer) = listener
            .accept()
            .map_err(|e| failed("accepting a connection", e))?;
        say(&format!("connection from {peer}"));
        return Ok(Box::new(BufReader::new(socket)));
    }
    if let Some(address) = input.strip_prefix("udp://") {
        let socket = UdpSocket::bind(address).map_err(|e| failed("binding", e))?;
        let local = socket.local_addr().map_err(|e| failed("binding", e))?;
        say(&format!("receiving on udp://{local}"));
        return Ok(Box::new(BufReader::new(Datagrams {
            socket,
            buffer: vec![0; 65_536],
            start: 0,
            end: 0,
        })));
    }
    let file = std::fs::File::open(input).map_err(|e| Error::from(DataError::io(input, e)))?;
    Ok(Box::new(BufReader::new(file)))
}

/// UDP datagrams read as one byte stream: each datagram's bytes in arrival order (a frame
/// split over datagrams joins up; an empty datagram ends the stream).
struct Datagrams {
    socket: UdpSocket,
    buffer: Vec<u8>,
    start: usize,
    end: usize,
}

impl Read for Datagrams {
    fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
        if self.start == self.end {
            self.end = self.socket.recv(&mut self.buffer)?;
            self.start = 0;
            if self.end == 0 {
                return Ok(0);
            }
        }
        let n = out.len().min(self.end - self.start);
        out[..n].copy_from_slice(&self.buffer[self.start..self.start + n]);
        self.start += n;
        Ok(n)
    }
}
