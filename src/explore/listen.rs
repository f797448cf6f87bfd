//! The server's connections, bounded so that slow or flooding clients
//! cannot starve the page: each must send a request's headers within
//! `HEADER_TIMEOUT`, and at most `MAX_CONNECTIONS` are open at once (past
//! it, new ones wait in the listen queue until one ends).

use axum::Router;
use hyper_util::rt::{TokioIo, TokioTimer};
use hyper_util::service::TowerToHyperService;
use std::sync::Arc;
use std::time::Duration;
use tokio::net::TcpListener;
use tokio::sync::Semaphore;

/// How long a client may take to send a request's headers, or to start
/// the next one on a kept-alive connection: the page sends each whole at
/// once.
pub const HEADER_TIMEOUT: Duration = Duration::from_secs(5);

/// The most connections open at once: the page keeps a few (its event
/// stream, a render, a key), and a process may have only 256 files open.
pub const MAX_CONNECTIONS: usize = 128;

/// Serves `router` on `listener` until the process ends.
pub async fn serve(listener: TcpListener, router: Router) -> std::io::Result<()> {
    let open = Arc::new(Semaphore::new(MAX_CONNECTIONS));
    loop {
        let permit = open
            .clone()
            .acquire_owned()
            .await
            .unwrap_or_else(|_| unreachable!("the semaphore is never closed"));
        let stream = match listener.accept().await {
            Ok((stream, _)) => stream,
            // Out of files or a connection reset before it was taken:
            // the next accept may succeed once a connection ends.
            Err(_) => {
                tokio::time::sleep(Duration::from_millis(50)).await;
                continue;
            }
        };
        let service = TowerToHyperService::new(router.clone());
        tokio::spawn(async move {
            let connection = hyper::server::conn::http1::Builder::new()
                .timer(TokioTimer::new())
                .header_read_timeout(HEADER_TIMEOUT)
                .serve_connection(TokioIo::new(stream), service);
            let _ = connection.await;
            drop(permit);
        });
    }
}
