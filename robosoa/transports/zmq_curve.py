"""Authentication and encryption of a ZeroMQ bus: CurveZMQ with pyzmq's own support.

Configured once per bus (``connect(url, curve_secret=, curve_allow=, curve_location=)`` or
the environment ``ROBOSOA_CURVE_SECRET``, ``ROBOSOA_CURVE_ALLOW``, ``ROBOSOA_CURVE_LOCATION``):
this participant's certificate (``NAME.key_secret``, made by ``robosoa keys``), a folder of
the public certificates (``*.key``) allowed on the bus, and the location service's public
certificate (default ``location.key`` in that folder). Every socket that binds is a CURVE
server whose ZAP handler (``zmq.auth.thread.ThreadAuthenticator``, started before anything is
bound) admits only allowed keys; every socket that connects is a CURVE client that checks the
server's key: the location service's from the configuration, providers' and publishers' from
their registrations (``ServiceInfo.key``), which only allowed participants could make.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path

import zmq
import zmq.auth
from zmq.auth.thread import ThreadAuthenticator

from robosoa.errors import RobosoaError

ENVIRONMENT = {"curve_secret": "ROBOSOA_CURVE_SECRET", "curve_allow": "ROBOSOA_CURVE_ALLOW",
               "curve_location": "ROBOSOA_CURVE_LOCATION"}


@dataclass(frozen=True, slots=True)
class Curve:
    """One participant's keys and the bus's allow-list."""

    public: bytes  # z85, 40 bytes
    secret: bytes
    allow: str  # folder of allowed public certificates
    location: bytes  # the location service's public key (z85); b"" for the service itself

    def serve(self, sock: zmq.Socket[bytes]) -> None:
        """Make a binding socket a CURVE server (clients are checked by the ZAP handler)."""
        sock.setsockopt(zmq.CURVE_SECRETKEY, self.secret)
        sock.setsockopt(zmq.CURVE_PUBLICKEY, self.public)
        sock.setsockopt(zmq.CURVE_SERVER, 1)

    def client(self, sock: zmq.Socket[bytes], server: bytes) -> None:
        """Make a connecting socket a CURVE client of the server whose public key is given
        (set before each ``connect``: ZeroMQ takes it at that moment)."""
        sock.setsockopt(zmq.CURVE_SECRETKEY, self.secret)
        sock.setsockopt(zmq.CURVE_PUBLICKEY, self.public)
        sock.setsockopt(zmq.CURVE_SERVERKEY, server)

    def authenticator(self, ctx: zmq.Context[zmq.Socket[bytes]]) -> ThreadAuthenticator:
        """The ZAP handler of ``ctx``, admitting the allowed keys; start it before binding."""
        auth = ThreadAuthenticator(ctx)
        auth.start()
        auth.configure_curve(domain="*", location=self.allow)
        return auth


def _read(path: str, what: str, secret: bool) -> tuple[bytes, bytes]:
    if not Path(path).is_file():
        raise RobosoaError(f"{what} {path!r}: no such file")
    try:
        public, private = zmq.auth.load_certificate(path)
    except (ValueError, OSError, UnicodeDecodeError) as exc:
        raise RobosoaError(f"{what} {path!r}: not a ZeroMQ certificate ({exc})") from None
    if secret and not private:
        raise RobosoaError(f"{what} {path!r} holds no secret key (use NAME.key_secret)")
    return public, private or b""


def load(secret: str, allow: str, location: str, server: bool = False) -> Curve | None:
    """The keys named by the options (or, for empty ones, the environment); None when no
    secret certificate is configured (no CURVE). Raises RobosoaError naming a bad file."""
    secret = secret or os.environ.get(ENVIRONMENT["curve_secret"], "")
    if not secret:
        return None
    allow = allow or os.environ.get(ENVIRONMENT["curve_allow"], "")
    if not allow or not Path(allow).is_dir():
        raise RobosoaError(f"CURVE allow-list folder {allow!r}: no such folder "
                           "(curve_allow, ROBOSOA_CURVE_ALLOW)")
    public, private = _read(secret, "CURVE certificate", secret=True)
    if server:
        return Curve(public, private, allow, b"")
    location = (location or os.environ.get(ENVIRONMENT["curve_location"], "")
                or str(Path(allow) / "location.key"))
    return Curve(public, private, allow, _read(location, "location certificate", False)[0])


def create(folder: str, name: str) -> tuple[str, str]:
    """Write ``NAME.key`` (public) and ``NAME.key_secret`` in ``folder``; never overwrites."""
    if not re.fullmatch(r"[A-Za-z0-9_.-]{1,64}", name) or name.startswith("."):
        raise RobosoaError(f"key name {name!r}: use letters, digits, '_', '-', '.' only")
    os.makedirs(folder, exist_ok=True)
    paths = (os.path.join(folder, f"{name}.key"), os.path.join(folder, f"{name}.key_secret"))
    for path in paths:
        if os.path.exists(path):
            raise RobosoaError(f"{path} exists already: not overwritten")
    public, secret = zmq.auth.create_certificates(folder, name)
    os.chmod(secret, 0o600)
    return public, secret
