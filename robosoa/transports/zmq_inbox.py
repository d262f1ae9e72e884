"""A provider instance's inbox over ZeroMQ: a ROUTER socket bound next to the location service."""

from __future__ import annotations

import uuid
from collections.abc import Callable

import zmq

from robosoa.errors import InvalidMessage
from robosoa.message import Kind, Message, decode_frames, encode_frames
from robosoa.transports.base import BusOptions, Inbox, Incoming
from robosoa.transports.zmq_curve import Curve
from robosoa.transports.zmq_guard import CURVE_FRAMING, FRAMING, Guard, budget
from robosoa.transports.zmq_sockets import (
    bind_provider,
    keepalive,
    limit_input,
    recv_rest,
    send_frames,
)

_NOBLOCK = int(zmq.NOBLOCK)  # plain ints: pyzmq's flag enums cost a little on every send
_MORE_NOBLOCK = int(zmq.SNDMORE | zmq.NOBLOCK)
_RCVMORE = int(zmq.RCVMORE)


class ZmqInbox(Inbox):
    """A provider ROUTER: a JSON frame (and its binary frames) per message, replies routed
    by identity.

    The serving thread blocks in ``recv`` (receive timeout); ``wake`` sends a secret token to
    our own endpoint, so no poller is needed on the hot path.
    """

    def __init__(self, ctx: zmq.Context[zmq.Socket[bytes]], location: str,
                 options: BusOptions, rejected: Callable[[str], None],
                 curve: Curve | None = None, guard: Guard | None = None,
                 cut: Callable[[str], None] = lambda peer: None) -> None:
        self._ctx = ctx
        self._options = options
        self._rejected = rejected
        self._router = ctx.socket(zmq.ROUTER)
        self._router.setsockopt(zmq.LINGER, 0)
        self._router.setsockopt(zmq.RCVHWM, options.inbox_size)
        self._router.setsockopt(zmq.SNDHWM, options.hwm)
        limit_input(self._router, options.max_message)
        keepalive(self._router, options.link_heartbeat, options.link_timeout)
        if curve is not None:
            curve.serve(self._router)
            self.key = curve.public.decode()
        self._curve = curve
        self.endpoint = bind_provider(self._router, location,
                                      options.provider_bind,
                                      options.advertise_host)
        self._bound = str(self._router.getsockopt_string(zmq.LAST_ENDPOINT))
        self._watch = None if guard is None else guard.watch(
            self._router, budget(options.total), FRAMING if curve is None else CURVE_FRAMING,
            cut)
        self._token = uuid.uuid4().bytes
        self._timeout = -2

    def receive(self, timeout: float) -> Incoming | None:
        wait = int(timeout * 1000)
        if wait != self._timeout:
            self._router.setsockopt(zmq.RCVTIMEO, wait)
            self._timeout = wait
        router = self._router
        try:
            identity = router.recv()
        except zmq.Again:
            return None
        watch, first = self._watch, None
        if not router.getsockopt(_RCVMORE):
            data = b""
        elif watch is None or identity in watch.fds:
            data = router.recv()
        else:  # a peer not seen before: its connection is found from a frame (ZMQ_SRCFD)
            first = router.recv(copy=False)
            data = first.bytes

        def reply(msg: Message) -> None:
            out = encode_frames(msg)
            router.send(identity, _MORE_NOBLOCK)
            send_frames(router, out, _NOBLOCK)

        try:
            frames = ([data] if not router.getsockopt(_RCVMORE) else
                      recv_rest(router, data, total=self._options.total))
            if watch is not None:
                size = len(data) if len(frames) == 1 else sum(map(len, frames))
                watch.took(identity, size, len(frames), first)
            if len(frames) == 1 and data == self._token:
                return None
            msg = decode_frames(frames, self._options.max_message, self._options.max_depth,
                                self._options.total)
        except InvalidMessage as exc:  # answered with an error reply by the provider
            self._rejected("inbox")
            return Incoming(None, str(exc), reply)
        return Incoming(msg, "", None if msg.kind is Kind.ONEWAY else reply)

    def wake(self) -> None:
        try:
            sock = self._ctx.socket(zmq.DEALER)
        except zmq.ZMQError:
            return  # context already gone: the receiver ends at its timeout anyway
        sock.setsockopt(zmq.LINGER, 1000)
        if self._curve is not None:  # our own key is on the allow-list
            self._curve.client(sock, self._curve.public)
        sock.connect(self._bound.replace("0.0.0.0", "127.0.0.1"))
        sock.send(self._token, zmq.NOBLOCK)
        sock.close()

    def close(self) -> None:
        self._router.close(0)
