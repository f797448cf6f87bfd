//! Who may use the server: requests that carry the page's token, name the
//! server by an address or `localhost` (a DNS name that points here, the
//! way DNS rebinding works, is refused) and come from its own origin.

use super::State;
use axum::extract::Request;
use axum::http::{header, HeaderMap, StatusCode};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use std::sync::Arc;

/// The header the page sends the token in (server-sent events and the
/// first load carry it in the query instead).
pub const TOKEN_HEADER: &str = "x-mandelreel-token";

/// The paths that take the token in the query: what a browser loads by
/// address (the page, its script and style) and the event stream, which
/// cannot send a header. Every other route takes it in `TOKEN_HEADER`
/// alone, so a link or a logged address can do no more than open the page.
const QUERY_TOKEN_PATHS: [&str; 4] = ["/", "/explore.js", "/explore.css", "/api/events"];

/// 128 random bits, as hex.
pub fn new_token() -> anyhow::Result<String> {
    let mut bytes = [0u8; 16];
    getrandom::fill(&mut bytes).map_err(|e| anyhow::anyhow!("no random token: {e}"))?;
    Ok(bytes.iter().map(|b| format!("{b:02x}")).collect())
}

/// Refuses a request that fails any check, with the reason.
pub async fn check(
    axum::extract::State(state): axum::extract::State<Arc<State>>,
    request: Request,
    next: Next,
) -> Response {
    let uri = request.uri();
    let query = uri
        .query()
        .filter(|_| QUERY_TOKEN_PATHS.contains(&uri.path()));
    match refusal(&state, request.headers(), query) {
        // Closed after the answer: a client without the token holds no
        // connection open by sending one complete request after another.
        Some(reason) => {
            let close = [(header::CONNECTION, "close")];
            (StatusCode::FORBIDDEN, close, reason).into_response()
        }
        None => next.run(request).await,
    }
}

/// Why a request is refused, if it is: `query` is the request's where it
/// may carry the token.
fn refusal(state: &State, headers: &HeaderMap, query: Option<&str>) -> Option<String> {
    let port = state.address.port();
    let host = headers.get(header::HOST).and_then(|h| h.to_str().ok());
    match host {
        Some(host) if host_is_ours(host, port) => {}
        other => return Some(format!("refused: Host {other:?} is not this server")),
    }
    if let Some(origin) = headers.get(header::ORIGIN) {
        let ours = origin
            .to_str()
            .ok()
            .and_then(|o| o.strip_prefix("http://"))
            .is_some_and(|o| o == host.unwrap_or_default());
        if !ours {
            return Some(format!(
                "refused: Origin {origin:?} is not this server's page"
            ));
        }
    }
    let given = headers
        .get(TOKEN_HEADER)
        .and_then(|t| t.to_str().ok())
        .or_else(|| query_token(query));
    if !given.is_some_and(|t| same(t.as_bytes(), state.token.as_bytes())) {
        return Some("refused: missing or wrong token; open the address explore printed".into());
    }
    None
}

/// A Host naming this server: an IP address or `localhost`, with our port.
fn host_is_ours(host: &str, port: u16) -> bool {
    let Some((name, given_port)) = host.rsplit_once(':') else {
        return false;
    };
    if given_port.parse() != Ok(port) {
        return false;
    }
    let name = name.trim_start_matches('[').trim_end_matches(']');
    name.eq_ignore_ascii_case("localhost") || name.parse::<std::net::IpAddr>().is_ok()
}

fn query_token(query: Option<&str>) -> Option<&str> {
    query?
        .split('&')
        .find_map(|pair| pair.strip_prefix("token="))
}

/// Equal, in time that does not depend on where they first differ.
fn same(a: &[u8], b: &[u8]) -> bool {
    a.len() == b.len() && a.iter().zip(b).fold(0, |d, (x, y)| d | (x ^ y)) == 0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hosts_are_addresses_or_localhost_on_our_port() {
        assert!(host_is_ours("127.0.0.1:8080", 8080));
        assert!(host_is_ours("localhost:8080", 8080));
        assert!(host_is_ours("[::1]:8080", 8080));
        assert!(!host_is_ours("127.0.0.1:8081", 8080));
        assert!(!host_is_ours("evil.example:8080", 8080));
        assert!(!host_is_ours("127.0.0.1", 8080));
    }

    #[test]
    fn tokens_are_random_and_compared_whole() {
        let (a, b) = (new_token().unwrap(), new_token().unwrap());
        assert_eq!(a.len(), 32);
        assert_ne!(a, b);
        assert!(same(a.as_bytes(), a.clone().as_bytes()));
        assert!(!same(a.as_bytes(), &a.as_bytes()[..31]));
        assert_eq!(query_token(Some("x=1&token=abc")), Some("abc"));
    }
}
