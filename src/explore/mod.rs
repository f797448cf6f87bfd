//! `explore`: a local web page that shows a timeline's frames as they are
//! changed, and edits the timeline's text. The server answers only its own
//! page (`guard`); the document and its edits (`document`), a view's scenes
//! (`view`), progressive renders (`renderer`), the HTTP routes (`routes`)
//! and the file watch (`watch`) each have a module.

mod document;
mod guard;
mod listen;
mod page;
mod renderer;
mod routes;
mod view;
mod watch;

use std::net::{IpAddr, SocketAddr};
use std::path::PathBuf;
use std::sync::Arc;

pub use document::Document;

/// What `mandelreel explore` was asked for.
pub struct Options {
    /// The timeline to open; none starts a new one, saved under a name.
    pub timeline: Option<PathBuf>,
    pub bind: IpAddr,
    /// 0: any free port.
    pub port: u16,
}

/// Everything the routes share.
pub struct State {
    pub token: String,
    pub address: SocketAddr,
    pub document: std::sync::Mutex<Document>,
    pub renders: renderer::Renders,
    pub events: tokio::sync::broadcast::Sender<Event>,
    /// Held by an edit from its snapshot to its result: edits take turns,
    /// while the other routes never wait on one.
    pub editing: tokio::sync::Mutex<()>,
    /// Playback frames render `PLAYING_AT_ONCE` at a time (a newer view
    /// does not stop them, as it stops the other stages): the page asks
    /// for one at a time, and a flood of them waits its turn.
    pub playing: tokio::sync::Semaphore,
}

/// Playback frames rendered at once: the page's one, and one left over
/// from a playback just stopped.
pub const PLAYING_AT_ONCE: usize = 2;

/// What the page is told without asking (server-sent events).
#[derive(Clone, Debug, serde::Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Event {
    /// The file changed on disk: taken in (`dirty` false), or kept apart
    /// from edits not yet saved (`dirty` true).
    File { dirty: bool, error: Option<String> },
    /// Rows done of the full-size stage in progress (`full` or `final`).
    Progress {
        done: u32,
        of: u32,
        stage: &'static str,
    },
}

/// Opens the timeline, listens, prints the page's address, and serves
/// until Ctrl-C or SIGTERM, which end the process as they end a render:
/// a save under way finishes or leaves nothing behind (`interrupt`).
pub fn serve(options: Options) -> anyhow::Result<()> {
    let _ = crate::interrupt::install();
    let document = Document::open(options.timeline.as_deref())?;
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()?;
    runtime.block_on(async move {
        let listener = tokio::net::TcpListener::bind((options.bind, options.port))
            .await
            .map_err(|e| {
                anyhow::anyhow!("cannot listen on {}:{}: {e}", options.bind, options.port)
            })?;
        let address = listener.local_addr()?;
        // `::` on most systems answers IPv4 as well.
        let dual_stack = address.is_ipv6()
            && socket2::SockRef::from(&listener)
                .only_v6()
                .is_ok_and(|only| !only);
        let state = Arc::new(State {
            token: guard::new_token()?,
            address,
            document: std::sync::Mutex::new(document),
            renders: renderer::Renders::default(),
            events: tokio::sync::broadcast::channel(64).0,
            editing: tokio::sync::Mutex::new(()),
            playing: tokio::sync::Semaphore::new(PLAYING_AT_ONCE),
        });
        announce(&state, dual_stack)?;
        tokio::spawn(watch::watch(state.clone()));
        listen::serve(listener, routes::router(state)).await?;
        Ok(())
    })
}

/// The addresses other machines reach a server bound to `bind` at: its
/// own, or where it is unspecified (0.0.0.0, ::) every interface's of its
/// family (of both, `dual_stack`) but loopback.
fn answering(bind: IpAddr, dual_stack: bool) -> Vec<IpAddr> {
    if !bind.is_unspecified() {
        return vec![bind];
    }
    let interfaces = if_addrs::get_if_addrs().unwrap_or_default();
    let mut ips: Vec<IpAddr> = interfaces
        .iter()
        .map(|i| i.ip())
        .filter(|ip| !ip.is_loopback() && (dual_stack || ip.is_ipv4() == bind.is_ipv4()))
        // A link-local IPv6 address needs its interface named in a URL.
        .filter(|ip| !matches!(ip, IpAddr::V6(v6) if v6.segments()[0] & 0xffc0 == 0xfe80))
        .collect();
    ips.sort();
    ips.dedup();
    ips
}

/// The address to open, on standard output (a script reads it from there).
fn announce(state: &State, dual_stack: bool) -> anyhow::Result<()> {
    use std::io::Write as _;
    let name = state.document.lock().expect("document").name();
    // Unspecified, it answers on the loopback of its own family.
    let host = match state.address.ip() {
        IpAddr::V4(ip) if ip.is_unspecified() => "127.0.0.1".to_string(),
        IpAddr::V6(ip) if ip.is_unspecified() => "[::1]".to_string(),
        IpAddr::V6(ip) => format!("[{ip}]"),
        ip => ip.to_string(),
    };
    let url = format!(
        "http://{host}:{}/?token={}",
        state.address.port(),
        state.token
    );
    // One write: a reader that takes the first line and goes cannot make
    // the second fail, which would end the server.
    let mut said = format!(
        "Exploring {name}: open {url}\n(Ctrl-C stops the server; edits not saved are lost.)\n"
    );
    if !state.address.ip().is_loopback() {
        let port = state.address.port();
        let urls: Vec<String> = answering(state.address.ip(), dual_stack)
            .into_iter()
            .map(|ip| {
                format!(
                    "http://{}/?token={}",
                    SocketAddr::new(ip, port),
                    state.token
                )
            })
            .collect();
        let urls = match urls.is_empty() {
            true => vec!["(no network interface found)".to_string()],
            false => urls,
        };
        said += &format!(
            "Other machines reach it at {}\nwarning: plain HTTP: anyone on the network between can read the page, its token and your edits\n",
            urls.join(" ")
        );
    }
    let mut out = std::io::stdout().lock();
    out.write_all(said.as_bytes())?;
    out.flush()?;
    Ok(())
}
