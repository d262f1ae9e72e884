"""The subscriber's feed hands out what it reads in batches: small messages together once the
socket is empty, large ones one by one (a batch of them would overflow a subscription's byte
budget before its reader could take any). Real ZeroMQ sockets on inproc; the feed's own
``_drain`` reads a SUB socket of the test's, whose class only counts the reads. And the
feed's way of taking a whole message off a socket (``recv_message``)."""

from __future__ import annotations

import json
import uuid
from collections.abc import Iterator
from typing import Any

import pytest
import zmq

from robosoa.message import Message
from robosoa.transports.base import BusOptions
from robosoa.transports.zmq_outlet import META
from robosoa.transports.zmq_pubsub import BATCH_BYTES, Feed
from robosoa.transports.zmq_sockets import recv_message

pytestmark = pytest.mark.timeout(60)


class CountingSocket(zmq.Socket[bytes]):
    """A real ZeroMQ socket that counts its ``recv`` calls: the frames taken off it, one per
    message in these tests (every message is one frame)."""

    reads = 0

    def recv(self, flags: int = 0, copy: bool = True, track: bool = False) -> Any:
        frame = super().recv(flags, copy, track)
        self.reads += 1
        return frame


@pytest.fixture()
def wired() -> Iterator[tuple[Feed, zmq.Socket[bytes], CountingSocket]]:
    """A feed (its own thread idle: nothing is published to its sockets) and a PUB -> SUB
    pair whose SUB the test drains with the feed's code."""
    ctx: zmq.Context[zmq.Socket[bytes]] = zmq.Context()
    feed = Feed(ctx, BusOptions(), lambda why: None, lambda channel, n: None,
                "inproc://no-announcements", lambda: None)
    address = f"inproc://feed-{uuid.uuid4().hex}"
    pub = ctx.socket(zmq.PUB)
    pub.bind(address)
    sub = CountingSocket(ctx, zmq.SUB)
    sub.setsockopt(zmq.SUBSCRIBE, b"t:scan\0")
    sub.connect(address)
    try:
        yield feed, pub, sub
    finally:
        feed.close()
        pub.close(0)
        sub.close(0)
        ctx.term()


def _publish(pub: zmq.Socket[bytes], seq: int, filler: int) -> None:
    body = json.dumps({"kind": "publish", "topic": "scan",
                       "payload": {"n": seq, "fill": "x" * filler}}).encode()
    pub.send(b"t:scan\0" + META.pack(1, seq, 0.0) + body)


def _drained(wired: tuple[Feed, zmq.Socket[bytes], CountingSocket], filler: int,
             count: int) -> list[tuple[int, int]]:
    """(message number, messages read off the socket when it was handed out), for ``count``
    messages of ``filler`` bytes published before the feed drains the socket once."""
    feed, pub, sub = wired
    handed: list[tuple[int, int]] = []

    def sink(msg: Message, size: int, expires: float, hold: bool) -> bool:
        handed.append((msg.payload["n"], sub.reads))
        return True

    feed.subscribe("t:scan", sink)
    _publish(pub, 0, 0)  # until the subscription has reached the PUB
    while not sub.poll(20):
        _publish(pub, 0, 0)
    for seq in range(1, count + 1):
        _publish(pub, seq, filler)
    while sub.poll(0):
        feed._drain(sub)
    return [(n, reads) for n, reads in handed if n]


def test_small_messages_are_handed_out_after_the_batch_is_read(
        wired: tuple[Feed, zmq.Socket[bytes], CountingSocket]) -> None:
    handed = _drained(wired, 100, 50)
    assert [n for n, _ in handed] == list(range(1, 51))
    assert len({reads for _, reads in handed}) == 1  # all at once, after the last read


def test_large_messages_are_handed_out_one_by_one(
        wired: tuple[Feed, zmq.Socket[bytes], CountingSocket]) -> None:
    handed = _drained(wired, BATCH_BYTES, 5)
    assert [n for n, _ in handed] == [1, 2, 3, 4, 5]
    reads = [r for _, r in handed]
    assert reads == list(range(reads[0], reads[0] + 5))  # each before the next is read


def test_a_sink_that_fails_loses_that_message_only(
        wired: tuple[Feed, zmq.Socket[bytes], CountingSocket]) -> None:
    """A sink raising on one message of a batch: that message is lost (to the sinks after
    it too), the batch's later messages are handed out in order and the drain returns (as
    when messages were handed out alone)."""
    feed, _, _ = wired

    def failing(msg: Message, size: int, expires: float, hold: bool) -> bool:
        if msg.payload["n"] == 3:
            raise RuntimeError("a sink's own bug")
        return True

    feed.subscribe("t:scan", failing)
    handed = _drained(wired, 100, 6)  # its recording sink comes after the failing one
    assert [n for n, _ in handed] == [1, 2, 4, 5, 6]
    assert len({reads for _, reads in handed}) == 1  # still one batch


def test_recv_message_takes_whole_messages_and_cuts_off_extra_frames() -> None:
    """One-frame messages, messages of several frames and one of more frames than allowed
    come off the socket whole, in order; the frames past the limit are read and thrown
    away (the message comes back one frame longer than the limit, which decoders refuse)."""
    ctx: zmq.Context[zmq.Socket[bytes]] = zmq.Context()
    pull, push = ctx.socket(zmq.PULL), ctx.socket(zmq.PUSH)
    address = f"inproc://recv-{uuid.uuid4().hex}"
    pull.bind(address)
    push.connect(address)
    try:
        push.send(b"one")
        push.send_multipart([b"head", b"a", b"b"])
        push.send_multipart([b"many", *[b"x"] * 10])
        push.send(b"last")
        assert recv_message(pull, 0, 4) == [b"one"]
        assert recv_message(pull, 0, 4) == [b"head", b"a", b"b"]
        assert recv_message(pull, 0, 4) == [b"many", b"x", b"x", b"x", b"x"]
        assert recv_message(pull, 0, 4) == [b"last"]
        with pytest.raises(zmq.Again):
            recv_message(pull, zmq.NOBLOCK, 4)
    finally:
        pull.close(0)
        push.close(0)
        ctx.term()
