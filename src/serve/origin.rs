//! Which requests the app answers: only those addressed to it by a name it
//! listens under (`Host`), and, when a browser says where the page that
//! sends them came from (`Origin`), only from its own page.
//!
//! A page on any other site the engineer has open could otherwise post to
//! `http://127.0.0.1:8230/api/...` (a cross-site request), and a name that a
//! rogue DNS server points at 127.0.0.1 could read the answers (DNS
//! rebinding); checking both headers refuses either. A client that sends no
//! `Origin` (curl, a script on the same machine) is not a browser page of
//! another site, and is answered.

use std::net::SocketAddr;

/// The `Host` values the app answers to, for a listener bound to `addr`:
/// `127.0.0.1:PORT`, `localhost:PORT` and `[::1]:PORT` on loopback, and the
/// address itself when `--listen` named another.
pub fn allowed_hosts(addr: SocketAddr) -> Vec<String> {
    let port = addr.port();
    let mut hosts = vec![
        format!("127.0.0.1:{port}"),
        format!("localhost:{port}"),
        format!("[::1]:{port}"),
    ];
    let own = addr.to_string();
    if !hosts.contains(&own) {
        hosts.push(own);
    }
    hosts
}

/// Why a request is refused, or `None` when it is answered.
pub fn refusal(allowed: &[String], host: Option<&str>, origin: Option<&str>) -> Option<String> {
    let host = host.map(str::to_ascii_lowercase);
    match &host {
        Some(host) if allowed.contains(host) => {}
        Some(host) => {
            return Some(format!(
                "refused: this app does not answer to host {host:?}"
            ));
        }
        None => return Some("refused: the request names no host".to_string()),
    }
    let origin = origin?;
    let own = allowed
        .iter()
        .any(|allowed| origin.eq_ignore_ascii_case(&format!("http://{allowed}")));
    (!own).then(|| format!("refused: requests from {origin:?} (another origin) are not answered"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn own_page_and_plain_clients_are_answered_others_refused() {
        let allowed = allowed_hosts("127.0.0.1:8230".parse().unwrap());
        assert_eq!(allowed.len(), 3);
        assert_eq!(refusal(&allowed, Some("127.0.0.1:8230"), None), None);
        assert_eq!(
            refusal(
                &allowed,
                Some("localhost:8230"),
                Some("http://localhost:8230")
            ),
            None
        );
        // Another site's page, a rebound name, another port, no Host at all.
        let other = refusal(
            &allowed,
            Some("127.0.0.1:8230"),
            Some("http://evil.example"),
        );
        assert!(other.unwrap().contains("another origin"));
        assert!(refusal(&allowed, Some("evil.example:8230"), None).is_some());
        assert!(refusal(&allowed, Some("127.0.0.1:8231"), None).is_some());
        assert!(refusal(&allowed, None, None).is_some());
        assert!(
            refusal(
                &allowed,
                Some("127.0.0.1:8230"),
                Some("http://127.0.0.1:8231")
            )
            .is_some()
        );
    }

    #[test]
    fn a_listen_address_is_its_own_host() {
        let allowed = allowed_hosts("192.0.2.7:9000".parse().unwrap());
        assert!(allowed.contains(&"192.0.2.7:9000".to_string()));
        assert_eq!(
            refusal(
                &allowed,
                Some("192.0.2.7:9000"),
                Some("http://192.0.2.7:9000")
            ),
            None
        );
    }
}
