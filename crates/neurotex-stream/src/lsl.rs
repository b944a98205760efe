//! The Lab Streaming Layer (LSL), the common bus of neuroscience rigs: a stream's samples
//! read from an LSL inlet (`--input lsl:NAME` or `lsl:type=Tactile`), and its decisions
//! published on an LSL outlet (`--publish lsl:NAME`).
//!
//! liblsl is a C++ library; it is loaded when a stream asks for it (`dlopen`), not linked,
//! so building neurotex needs no LSL and a machine without it loses only these inputs. It is
//! found as pylsl finds it: the file `PYLSL_LIB` names, else the system's `liblsl.so`
//! (pylsl's wheel bundles one: `python -c "import pylsl.lib as l, os;
//! print(os.path.dirname(l.__file__))"`). Only the C API's few calls below are used, each
//! with the signature of liblsl's `lsl_c.h` (1.13 and later).

use std::ffi::{c_char, c_void, CStr, CString};
use std::sync::Arc;

use neurotex_core::events::Stamp;

use crate::error::{DataError, Result};
use crate::events::{marker_item, EventInput, Item};
use crate::frames::{Frame, FrameSource};
use crate::recording::TimeUnit;

/// liblsl's channel formats.
const CF_FLOAT32: i32 = 1;
const CF_STRING: i32 = 3;
const CF_INT64: i32 = 7;
/// liblsl's error codes.
const LSL_TIMEOUT_ERROR: i32 = -1;
const LSL_LOST_ERROR: i32 = -2;

type Handle = *mut c_void;

/// The C API's calls neurotex makes, resolved once from the loaded library.
struct Api {
    resolve_byprop:
        unsafe extern "C" fn(*mut Handle, u32, *const c_char, *const c_char, i32, f64) -> i32,
    get_channel_count: unsafe extern "C" fn(Handle) -> i32,
    get_channel_format: unsafe extern "C" fn(Handle) -> i32,
    get_name: unsafe extern "C" fn(Handle) -> *const c_char,
    destroy_streaminfo: unsafe extern "C" fn(Handle),
    create_inlet: unsafe extern "C" fn(Handle, i32, i32, i32) -> Handle,
    destroy_inlet: unsafe extern "C" fn(Handle),
    open_stream: unsafe extern "C" fn(Handle, f64, *mut i32),
    pull_sample_d: unsafe extern "C" fn(Handle, *mut f64, i32, f64, *mut i32) -> f64,
    pull_chunk_d: unsafe extern "C" fn(
        Handle,
        *mut f64,
        *mut f64,
        std::ffi::c_ulong,
        std::ffi::c_ulong,
        f64,
        *mut i32,
    ) -> std::ffi::c_ulong,
    pull_sample_str: unsafe extern "C" fn(Handle, *mut *mut c_char, i32, f64, *mut i32) -> f64,
    destroy_string: unsafe extern "C" fn(*mut c_char),
    create_streaminfo:
        unsafe extern "C" fn(*const c_char, *const c_char, i32, f64, i32, *const c_char) -> Handle,
    create_outlet: unsafe extern "C" fn(Handle, i32, i32) -> Handle,
    destroy_outlet: unsafe extern "C" fn(Handle),
    push_sample_str: unsafe extern "C" fn(Handle, *const *const c_char) -> i32,
    have_consumers: unsafe extern "C" fn(Handle) -> i32,
}

/// liblsl, loaded.
pub struct Lsl {
    api: Api,
    /// Kept loaded while the calls above may run.
    _library: libloading::Library,
}

impl std::fmt::Debug for Lsl {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Lsl")
    }
}

impl Lsl {
    /// Loads liblsl: `PYLSL_LIB`'s file, else the system's.
    ///
    /// # Errors
    /// No liblsl found, or one without the calls used.
    pub fn load() -> std::result::Result<Arc<Self>, String> {
        let named = std::env::var_os("PYLSL_LIB");
        let candidates: Vec<std::ffi::OsString> = match &named {
            Some(path) => vec![path.clone()],
            None => ["liblsl.so", "liblsl.so.2", "liblsl.dylib", "lsl.dll"]
                .iter()
                .map(Into::into)
                .collect(),
        };
        let mut failed = Vec::new();
        for candidate in &candidates {
            // SAFETY: loading runs the library's initialisers; liblsl's only set up its own
            // state.
            match unsafe { libloading::Library::new(candidate) } {
                Ok(library) => return Self::bind(library),
                Err(e) => failed.push(e.to_string()),
            }
        }
        Err(format!(
            "the Lab Streaming Layer's library (liblsl) was not found ({}): `pip install pylsl` bundles it; point PYLSL_LIB at it (the liblsl.so beside pylsl/lib/__init__.py), or install your system's liblsl",
            failed.join("; ")
        ))
    }

    fn bind(library: libloading::Library) -> std::result::Result<Arc<Self>, String> {
        macro_rules! get {
            ($name:literal) => {
                // SAFETY: the symbol is liblsl's C function of that name, whose signature
                // (lsl_c.h) is the field's type.
                *unsafe { library.get($name) }.map_err(|e| format!("liblsl lacks a call: {e}"))?
            };
        }
        // liblsl logs its own state (configuration, reconnections) to standard error; a
        // stream says what matters itself. A person's LSLAPICFG is left to rule.
        if std::env::var_os("LSLAPICFG").is_none() {
            // SAFETY: the symbol is liblsl's `int32_t lsl_set_config_content(const char*)`,
            // called before any other call, with a NUL-terminated string.
            if let Ok(set) = unsafe {
                library
                    .get::<unsafe extern "C" fn(*const c_char) -> i32>(b"lsl_set_config_content\0")
            } {
                unsafe { set(c"[log]\nlevel = -3\n".as_ptr()) };
            }
        }
        let api = Api {
            resolve_byprop: get!(b"lsl_resolve_byprop\0"),
            get_channel_count: get!(b"lsl_get_channel_count\0"),
            get_channel_format: get!(b"lsl_get_channel_format\0"),
            get_name: get!(b"lsl_get_name\0"),
            destroy_streaminfo: get!(b"lsl_destroy_streaminfo\0"),
            create_inlet: get!(b"lsl_create_inlet\0"),
            destroy_inlet: get!(b"lsl_destroy_inlet\0"),
            open_stream: get!(b"lsl_open_stream\0"),
            pull_sample_d: get!(b"lsl_pull_sample_d\0"),
            pull_chunk_d: get!(b"lsl_pull_chunk_d\0"),
            pull_sample_str: get!(b"lsl_pull_sample_str\0"),
            destroy_string: get!(b"lsl_destroy_string\0"),
            create_streaminfo: get!(b"lsl_create_streaminfo\0"),
            create_outlet: get!(b"lsl_create_outlet\0"),
            destroy_outlet: get!(b"lsl_destroy_outlet\0"),
            push_sample_str: get!(b"lsl_push_sample_str\0"),
            have_consumers: get!(b"lsl_have_consumers\0"),
        };
        Ok(Arc::new(Lsl {
            api,
            _library: library,
        }))
    }
}

/// What the LSL names a stream or an outlet by cannot do.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum LslError {
    /// `lsl:TEXT` whose text names no stream (an empty name or value, or a NUL byte).
    #[error(
        "`lsl:{0}` names no stream: `lsl:NAME` or `lsl:PROPERTY=VALUE` (such as lsl:type=Tactile)"
    )]
    NoStream(String),
    /// An outlet's name holding a NUL byte.
    #[error("`{0}` holds a NUL byte")]
    NulByte(String),
    /// liblsl could not describe the outlet's stream.
    #[error("liblsl could not describe the stream `{0}`")]
    Describe(String),
    /// liblsl could not open the outlet.
    #[error("liblsl could not open the outlet `{0}`")]
    Open(String),
}

/// Which stream to read: `NAME`, or `PROPERTY=VALUE` (`type=Tactile`, `source_id=...`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Query {
    /// The stream property matched.
    pub property: String,
    /// Its value.
    pub value: String,
}

impl Query {
    /// The query of `lsl:TEXT`'s text.
    ///
    /// # Errors
    /// An empty name or value, or a NUL byte.
    pub fn parse(text: &str) -> std::result::Result<Self, LslError> {
        let (property, value) = match text.split_once('=') {
            Some((p, v)) => (p.trim(), v.trim()),
            None => ("name", text.trim()),
        };
        if property.is_empty() || value.is_empty() || text.contains('\0') {
            return Err(LslError::NoStream(text.to_string()));
        }
        Ok(Query {
            property: property.into(),
            value: value.into(),
        })
    }
}

impl std::fmt::Display for Query {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.property.as_str() {
            "name" => write!(f, "lsl:{}", self.value),
            p => write!(f, "lsl:{p}={}", self.value),
        }
    }
}

/// What a pull found.
#[derive(Debug, PartialEq)]
pub enum Pulled {
    /// A numeric sample stamped by the sender's LSL clock (s); its channels are
    /// [`Inlet::values`].
    Values(f64),
    /// A marker (string) sample: its stamp and its first channel.
    Text(f64, String),
    /// None within the wait.
    Nothing,
    /// The stream is gone: its outlet closed, or its host can no longer be reached.
    Lost,
}

/// An inlet on one LSL stream.
pub struct Inlet {
    lsl: Arc<Lsl>,
    handle: Handle,
    /// The stream, as found (`lsl:NAME`).
    pub query: Query,
    /// The stream's name.
    pub name: String,
    /// Its channels.
    pub channels: usize,
    /// Whether it carries text (a marker stream).
    pub text: bool,
    values: Vec<f64>,
    /// Samples pulled as a chunk and not yet taken: their values and stamps, and the next.
    chunk: Vec<f64>,
    stamps: Vec<f64>,
    next: usize,
}

/// The samples one chunk pull takes at most.
const CHUNK: usize = 1024;

impl std::fmt::Debug for Inlet {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Inlet({})", self.query)
    }
}

// SAFETY: an inlet is used by one thread at a time (it moves with its stream); liblsl's
// inlets may be used from any thread.
unsafe impl Send for Inlet {}

impl Inlet {
    /// Resolves `query` for up to `timeout_s` and opens an inlet on the first stream found.
    /// Its stamps are the sender's, on its LSL clock, without post-processing: a stream
    /// uses only their differences, which a clock offset does not change and smoothing
    /// would.
    ///
    /// # Errors
    /// No stream found, or a channel format neurotex cannot read (numbers or text).
    pub fn open(lsl: &Arc<Lsl>, query: &Query, timeout_s: f64) -> Result<Self> {
        let api = &lsl.api;
        let source = query.to_string();
        let fail = |why: String| crate::Error::from(DataError::invalid(&source, why));
        let property = CString::new(query.property.as_str()).map_err(|e| fail(e.to_string()))?;
        let value = CString::new(query.value.as_str()).map_err(|e| fail(e.to_string()))?;
        let mut found: [Handle; 8] = [std::ptr::null_mut(); 8];
        // SAFETY: `found` holds 8 handles; the strings are NUL-terminated and outlive the call.
        let n = unsafe {
            (api.resolve_byprop)(
                found.as_mut_ptr(),
                8,
                property.as_ptr(),
                value.as_ptr(),
                1,
                timeout_s,
            )
        };
        let n = usize::try_from(n).unwrap_or(0).min(found.len());
        if n == 0 {
            return Err(fail(format!(
                "no LSL stream with {} `{}` was found within {timeout_s} s (is its outlet running, on this network?)",
                query.property, query.value
            )));
        }
        let info = found[0];
        // SAFETY: `info` is a stream info liblsl returned; each found one is destroyed once,
        // after the inlet (which keeps a copy) is made.
        let (channels, format, name, handle) = unsafe {
            let channels = (api.get_channel_count)(info);
            let format = (api.get_channel_format)(info);
            let name = CStr::from_ptr((api.get_name)(info))
                .to_string_lossy()
                .into_owned();
            let handle = (api.create_inlet)(info, 360, 0, 0);
            for &other in &found[..n] {
                (api.destroy_streaminfo)(other);
            }
            (channels, format, name, handle)
        };
        if handle.is_null() {
            return Err(fail("liblsl could not open an inlet on it".into()));
        }
        let inlet = Inlet {
            lsl: Arc::clone(lsl),
            handle,
            query: query.clone(),
            name,
            channels: usize::try_from(channels).unwrap_or(0),
            text: format == CF_STRING,
            values: vec![0.0; usize::try_from(channels).unwrap_or(0)],
            chunk: vec![0.0; CHUNK * usize::try_from(channels).unwrap_or(0)],
            stamps: Vec::new(),
            next: 0,
        };
        if !(CF_FLOAT32..=CF_INT64).contains(&format) {
            return Err(fail(format!(
                "its channel format ({format}) is none liblsl defines"
            )));
        }
        let mut ec = 0;
        // SAFETY: a live inlet; `ec` is written by the call.
        unsafe {
            (api.open_stream)(inlet.handle, timeout_s, &mut ec);
        }
        if ec != 0 {
            return Err(fail(format!(
                "its data could not be subscribed to (liblsl error {ec})"
            )));
        }
        Ok(inlet)
    }

    /// The next sample, waiting up to `wait_s` for one.
    pub fn pull(&mut self, wait_s: f64) -> Pulled {
        if !self.text {
            if let Some(stamp) = self.next_in_chunk() {
                return Pulled::Values(stamp);
            }
        }
        let api = &self.lsl.api;
        let mut ec = 0;
        let stamp = match self.text {
            false => {
                let n = i32::try_from(self.values.len()).unwrap_or(i32::MAX);
                // SAFETY: a live inlet; `values` holds the stream's channel count.
                unsafe {
                    (api.pull_sample_d)(self.handle, self.values.as_mut_ptr(), n, wait_s, &mut ec)
                }
            }
            true => {
                let mut strings: Vec<*mut c_char> =
                    vec![std::ptr::null_mut(); self.channels.max(1)];
                let n = i32::try_from(strings.len()).unwrap_or(i32::MAX);
                // SAFETY: a live inlet; `strings` holds a pointer per channel, each string
                // liblsl allocates destroyed below.
                let stamp = unsafe {
                    (api.pull_sample_str)(self.handle, strings.as_mut_ptr(), n, wait_s, &mut ec)
                };
                let mut first = String::new();
                for (i, &s) in strings.iter().enumerate().filter(|(_, s)| !s.is_null()) {
                    // SAFETY: a NUL-terminated string liblsl made for this sample.
                    unsafe {
                        if i == 0 {
                            first = CStr::from_ptr(s).to_string_lossy().into_owned();
                        }
                        (api.destroy_string)(s);
                    }
                }
                if ec == 0 && stamp != 0.0 {
                    return Pulled::Text(stamp, first);
                }
                stamp
            }
        };
        match ec {
            LSL_LOST_ERROR => Pulled::Lost,
            0 | LSL_TIMEOUT_ERROR if stamp == 0.0 => Pulled::Nothing,
            0 => Pulled::Values(stamp),
            _ => Pulled::Lost,
        }
    }
}

impl Inlet {
    /// The next sample of a chunk, pulled at once when the last is used up: what has
    /// arrived, without waiting. `None` when nothing has.
    fn next_in_chunk(&mut self) -> Option<f64> {
        let channels = self.values.len();
        if self.next >= self.stamps.len() {
            self.stamps.resize(CHUNK, 0.0);
            let mut ec = 0;
            // SAFETY: a live inlet; `chunk` holds CHUNK samples of `channels` values and
            // `stamps` CHUNK stamps.
            let n = unsafe {
                (self.lsl.api.pull_chunk_d)(
                    self.handle,
                    self.chunk.as_mut_ptr(),
                    self.stamps.as_mut_ptr(),
                    self.chunk.len() as std::ffi::c_ulong,
                    CHUNK as std::ffi::c_ulong,
                    0.0,
                    &mut ec,
                )
            };
            let samples = match (ec, channels) {
                (0, 1..) => (n as usize / channels).min(CHUNK),
                _ => 0,
            };
            self.stamps.truncate(samples);
            self.next = 0;
        }
        let i = self.next;
        let stamp = *self.stamps.get(i)?;
        self.values
            .copy_from_slice(&self.chunk[i * channels..(i + 1) * channels]);
        self.next += 1;
        Some(stamp)
    }

    /// The last numeric sample's channels.
    pub fn values(&self) -> &[f64] {
        &self.values
    }
}

impl Drop for Inlet {
    fn drop(&mut self) {
        // SAFETY: the inlet is live and destroyed once.
        unsafe { (self.lsl.api.destroy_inlet)(self.handle) }
    }
}

/// An outlet publishing text samples: a marker stream of one string channel.
pub struct Outlet {
    lsl: Arc<Lsl>,
    handle: Handle,
}

impl std::fmt::Debug for Outlet {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Outlet")
    }
}

// SAFETY: as for `Inlet`.
unsafe impl Send for Outlet {}

impl Outlet {
    /// A marker stream named `name` (type `Markers`, one string channel, irregular rate).
    ///
    /// # Errors
    /// liblsl could not make it.
    pub fn new(lsl: &Arc<Lsl>, name: &str) -> std::result::Result<Self, LslError> {
        let api = &lsl.api;
        let c = |s: &str| CString::new(s).map_err(|_| LslError::NulByte(name.to_string()));
        let (n, kind, id) = (c(name)?, c("Markers")?, c(&format!("neurotex-{name}"))?);
        // SAFETY: NUL-terminated strings that outlive the calls; the info is copied by the
        // outlet and destroyed once.
        let handle = unsafe {
            let info =
                (api.create_streaminfo)(n.as_ptr(), kind.as_ptr(), 1, 0.0, CF_STRING, id.as_ptr());
            if info.is_null() {
                return Err(LslError::Describe(name.to_string()));
            }
            let handle = (api.create_outlet)(info, 0, 360);
            (api.destroy_streaminfo)(info);
            handle
        };
        if handle.is_null() {
            return Err(LslError::Open(name.to_string()));
        }
        Ok(Outlet {
            lsl: Arc::clone(lsl),
            handle,
        })
    }

    /// Waits up to `timeout_s` for a first consumer: lines pushed before one connects are
    /// lost. Whether one connected.
    pub fn wait_for_consumers(&self, timeout_s: f64) -> bool {
        let start = std::time::Instant::now();
        // SAFETY: a live outlet.
        while unsafe { (self.lsl.api.have_consumers)(self.handle) } == 0 {
            if start.elapsed().as_secs_f64() >= timeout_s {
                return false;
            }
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
        true
    }

    /// Publishes one line.
    pub fn push(&self, line: &str) {
        let Ok(text) = CString::new(line) else {
            return;
        };
        let sample = [text.as_ptr()];
        // SAFETY: a live outlet of one string channel; the string outlives the call.
        unsafe { (self.lsl.api.push_sample_str)(self.handle, sample.as_ptr()) };
    }
}

impl Drop for Outlet {
    /// Closes the outlet, after giving its consumers time to take the last lines: liblsl
    /// drops what it has not sent when an outlet is destroyed.
    fn drop(&mut self) {
        // SAFETY: the outlet is live and destroyed once.
        unsafe {
            if (self.lsl.api.have_consumers)(self.handle) != 0 {
                std::thread::sleep(std::time::Duration::from_millis(500));
            }
            (self.lsl.api.destroy_outlet)(self.handle)
        }
    }
}

/// How long a lost stream is looked for again before the input ends, s.
const REFIND_S: f64 = 3.0;

/// How long one search for a lost stream waits: the searches repeat until [`REFIND_S`], as
/// the first may find the closed outlet still announced, and opening it fails.
const SEARCH_S: f64 = 0.25;

/// How long one pull waits before looking at `stop()` again, s.
const PULL_WAIT_S: f64 = 0.1;

/// An inlet whose stream may come back: a lost stream is looked for again once, and must
/// come back with the channels it had.
struct Live {
    lsl: Arc<Lsl>,
    inlet: Inlet,
    samples: u64,
    ended: Option<String>,
}

impl Live {
    /// The next sample; `None` once `stop()` says so or the stream is gone for good.
    fn pull(&mut self, stop: &dyn Fn() -> bool) -> Result<Option<Pulled>> {
        loop {
            if stop() {
                return Ok(None);
            }
            match self.inlet.pull(PULL_WAIT_S) {
                Pulled::Nothing => continue,
                Pulled::Lost => {
                    if !self.refind()? {
                        return Ok(None);
                    }
                }
                sample => {
                    self.samples += 1;
                    return Ok(Some(sample));
                }
            }
        }
    }

    /// Looks for the lost stream again: `true` when it is back with the same channels.
    fn refind(&mut self) -> Result<bool> {
        let query = self.inlet.query.clone();
        let start = std::time::Instant::now();
        let inlet = loop {
            if let Ok(inlet) = Inlet::open(&self.lsl, &query, SEARCH_S) {
                break inlet;
            }
            if start.elapsed().as_secs_f64() >= REFIND_S {
                self.ended = Some(format!(
                    "{query}: the stream is gone (its outlet closed, or its host cannot be reached for {REFIND_S} s): the input ended"
                ));
                return Ok(false);
            }
            std::thread::sleep(std::time::Duration::from_secs_f64(SEARCH_S / 2.0));
        };
        let (was, now) = (self.inlet.channels, inlet.channels);
        if was != now || self.inlet.text != inlet.text {
            let kind = |text| if text { "text" } else { "numeric" };
            let why = format!(
                "the stream came back with {now} {} channel(s); it had {was} {} channel(s)",
                kind(inlet.text),
                kind(self.inlet.text),
            );
            return Err(DataError::invalid(query.to_string(), why).into());
        }
        self.inlet = inlet;
        Ok(true)
    }
}

/// Frames from an LSL stream of one numeric channel per taxel, stamped by the sender's
/// LSL clock; a sample whose every channel is NaN ends the episode.
pub struct LslFrames(Live);

impl LslFrames {
    /// Opens `query` (waiting up to `timeout_s` for it), checked to carry `channels`
    /// numbers per sample.
    ///
    /// # Errors
    /// No liblsl, no such stream, a marker stream, or another channel count.
    pub fn open(query: &Query, channels: usize, timeout_s: f64) -> Result<Self> {
        let (lsl, inlet) = open_checked(query, timeout_s)?;
        if inlet.text || inlet.channels != channels {
            let why = format!(
                "the stream carries {} {} channel(s) per sample; the model reads {channels} numbers, one per taxel{}",
                inlet.channels,
                if inlet.text { "text" } else { "numeric" },
                if inlet.text { " (a marker stream of events streams with --format events)" } else { "" },
            );
            return Err(DataError::invalid(query.to_string(), why).into());
        }
        Ok(LslFrames(Live {
            lsl,
            inlet,
            samples: 0,
            ended: None,
        }))
    }
}

/// liblsl loaded and `query`'s inlet opened.
fn open_checked(query: &Query, timeout_s: f64) -> Result<(Arc<Lsl>, Inlet)> {
    let lsl = Lsl::load().map_err(|why| DataError::invalid(query.to_string(), why))?;
    let inlet = Inlet::open(&lsl, query, timeout_s)?;
    Ok((lsl, inlet))
}

impl FrameSource for LslFrames {
    fn next_frame(&mut self, stop: &dyn Fn() -> bool) -> Result<Option<Frame<'_>>> {
        let Some(Pulled::Values(stamp)) = self.0.pull(stop)? else {
            return Ok(None);
        };
        let values = self.0.inlet.values();
        if values.iter().all(|v| v.is_nan()) {
            return Ok(Some(Frame::Reset));
        }
        Ok(Some(Frame::Values {
            stamp: Some(stamp),
            unit: TimeUnit::Seconds,
            values,
        }))
    }

    fn place(&self) -> String {
        format!("{} sample {}", self.0.inlet.query, self.0.samples)
    }

    fn ended(&self) -> Option<String> {
        self.0.ended.clone()
    }
}

/// Events from an LSL stream, stamped by the sender's LSL clock: a marker stream whose
/// strings are `x,y,p` (or `taxel,p`; an empty string is a tick, `reset` ends the
/// episode), or a numeric stream of `x, y[, p]` (or `taxel[, p]`) channels.
pub struct LslEvents {
    live: Live,
    taxel: bool,
}

impl LslEvents {
    /// Opens `query` (waiting up to `timeout_s` for it); `taxel`: events name a taxel
    /// index, not `x` and `y`.
    ///
    /// # Errors
    /// No liblsl, no such stream, or a numeric stream of another channel count.
    pub fn open(query: &Query, taxel: bool, timeout_s: f64) -> Result<Self> {
        let (lsl, inlet) = open_checked(query, timeout_s)?;
        let fits = match taxel {
            true => (1..=2).contains(&inlet.channels),
            false => (2..=3).contains(&inlet.channels),
        };
        if !inlet.text && !fits {
            let why = format!(
                "the stream carries {} numeric channel(s) per sample; events are {} (or a marker stream of such text)",
                inlet.channels,
                if taxel { "taxel[, p]" } else { "x, y[, p]" }
            );
            return Err(DataError::invalid(query.to_string(), why).into());
        }
        Ok(LslEvents {
            live: Live {
                lsl,
                inlet,
                samples: 0,
                ended: None,
            },
            taxel,
        })
    }
}

impl EventInput for LslEvents {
    fn next_item(&mut self, stop: &dyn Fn() -> bool) -> Result<Option<Item>> {
        let item = match self.live.pull(stop)? {
            Some(Pulled::Text(stamp, text)) => marker_item(stamp, &text, self.taxel),
            Some(Pulled::Values(stamp)) => {
                let v = self.live.inlet.values();
                let whole = |x: f64| (x.fract() == 0.0 && x.abs() < 9e15).then_some(x as i64);
                let fields: Option<Vec<i64>> = v.iter().map(|&x| whole(x)).collect();
                match fields {
                    None => Err("a channel is not a whole number".to_string()),
                    Some(f) => {
                        let (a, b, p) = match (self.taxel, f.as_slice()) {
                            (true, [a]) => (*a, 0, None),
                            (true, [a, p]) => (*a, 0, Some(*p)),
                            (false, [x, y]) => (*x, *y, None),
                            (_, [x, y, p, ..]) => (*x, *y, Some(*p)),
                            _ => (0, 0, None),
                        };
                        Ok(Item::Event {
                            stamp: Stamp::Float(stamp),
                            address: Some((a, b, p)),
                        })
                    }
                }
            }
            _ => return Ok(None),
        };
        Ok(Some(item.unwrap_or_else(|why| Item::Bad {
            place: self.place(),
            why,
        })))
    }

    fn place(&self) -> String {
        format!("{} sample {}", self.live.inlet.query, self.live.samples)
    }

    fn unit(&self) -> TimeUnit {
        TimeUnit::Seconds
    }

    fn ended(&self) -> Option<String> {
        self.live.ended.clone()
    }
}
