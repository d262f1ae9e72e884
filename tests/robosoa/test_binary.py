"""Binary payloads: bytes travel as ZeroMQ frames of their own beside the JSON, on every
pattern and transport; a peer's frames are checked before they are believed."""

from __future__ import annotations

import json
import os
from typing import Any

import pytest
import zmq

import robosoa
from robosoa import blobs
from robosoa.descriptor import DescriptorError, loads
from robosoa.message import Kind, Message, decode_frames, encode_frames
from tests.robosoa.conftest import FAST
from tests.robosoa.util import eventually

pytestmark = pytest.mark.timeout(60)

Pair = tuple[robosoa.Bus, robosoa.Bus]


def test_binary_values_are_cut_out_of_the_json_and_put_back() -> None:
    image = os.urandom(1000)
    payload: dict[str, Any] = {"image": image, "meta": {"thumb": bytearray(b"ab"), "n": 1},
                               "tiles": [b"", memoryview(b"xy"), "text"], "none": None}
    frames = encode_frames(Message(Kind.REQUEST, "cam", "snap", payload=payload))
    head = json.loads(frames[0])
    assert head["payload"] == {"image": None, "meta": {"thumb": None, "n": 1},
                               "tiles": [None, None, "text"], "none": None}
    assert head["blobs"] == [["image"], ["meta", "thumb"], ["tiles", 0], ["tiles", 1]]
    assert frames[1:] == [image, b"ab", b"", b"xy"]
    assert isinstance(payload["meta"]["thumb"], bytearray)  # the caller's payload is untouched
    back = decode_frames(frames)
    assert back.payload == {"image": image, "meta": {"thumb": b"ab", "n": 1},
                            "tiles": [b"", b"xy", "text"], "none": None}
    assert len(encode_frames(Message(Kind.REQUEST, payload={"n": 1}))) == 1  # no blobs: 1 frame


@pytest.mark.parametrize(("paths", "frames", "why"), [
    ([["a"]], [], "declares 1 binary values but carries 0"),
    ("a", [b"x"], "declares malformed"),
    ([[]], [b"x"], "non-empty list"),
    ([["a", 0]], [b"x"], "does not match"),
    ([["n"]], [b"x"], "does not lead to a null"),
    ([["a"], ["a"]], [b"x", b"y"], "does not lead to a null"),
    ([["missing"]], [b"x"], "does not match"),
    ([["l", 5]], [b"x"], "does not match"),
    ([["l", "0"]], [b"x"], "does not match"),
])
def test_a_peers_binary_frames_must_match_its_declared_paths(paths: Any, frames: list[bytes],
                                                             why: str) -> None:
    payload = {"a": None, "n": 1, "l": [None]}
    with pytest.raises(robosoa.InvalidMessage, match=why):
        blobs.join(payload, paths, frames)


def test_too_many_binary_values_are_refused_before_sending() -> None:
    many = {"parts": [b"x"] * (blobs.MAX_BLOBS + 1)}
    with pytest.raises(robosoa.InvalidMessage, match="binary values"):
        encode_frames(Message(Kind.REQUEST, payload=many))
    head = json.dumps({"kind": "request", "blobs": []}).encode()
    with pytest.raises(robosoa.InvalidMessage, match="frames"):
        decode_frames([head] + [b"x"] * (blobs.MAX_BLOBS + 1))


def test_bytes_in_requests_replies_topics_and_events(pair: Pair, name: str) -> None:
    a, b = pair
    big = os.urandom(3 * 1024 * 1024 + 7)
    a.provide(name, {"flip": lambda data, parts: {"data": data[::-1], "parts": parts[::-1],
                                                   "sizes": [len(p) for p in parts]}})
    reply = b.request(name, "flip", {"data": big, "parts": [b"", bytearray(b"\x00"), {"k": b"v"}]},
                      timeout=20)
    assert reply["data"] == big[::-1] and type(reply["data"]) is bytes
    assert reply["parts"] == [{"k": b"v"}, b"\x00", b""]
    got: list[robosoa.Message] = []
    b.subscribe(name, got.append)
    b.on(name, got.append)

    def both() -> bool:
        a.publish(name, {"frame": b"\x01\x02", "n": 1})
        a.emit(name, {"alarm": memoryview(b"\xff")})
        return {m.kind for m in got} == {robosoa.Kind.PUBLISH, robosoa.Kind.EVENT}

    eventually(both)
    payloads = {m.kind: m.payload for m in got}
    assert payloads[robosoa.Kind.PUBLISH] == {"frame": b"\x01\x02", "n": 1}
    assert payloads[robosoa.Kind.EVENT] == {"alarm": b"\xff"}


def test_on_the_wire_bytes_are_a_frame_not_base64(zmq_url: str, name: str) -> None:
    marker = b"\x00\xffRAW-MARKER\x80" * 100
    ctx: zmq.Context[zmq.Socket[bytes]] = zmq.Context()
    dealer = ctx.socket(zmq.DEALER)
    dealer.setsockopt(zmq.LINGER, 0)
    try:
        with robosoa.connect(zmq_url, **FAST) as bus:
            handle = bus.provide(name, {"echo": lambda blob: {"blob": blob, "size": len(blob)}})
            dealer.connect(handle.endpoint)
            head = {"kind": "request", "operation": "echo", "payload": {"blob": None},
                    "blobs": [["blob"]]}
            dealer.send_multipart([json.dumps(head).encode(), marker])
            assert dealer.poll(5000)
            frames = dealer.recv_multipart()
    finally:
        dealer.close(0)
        ctx.term()
    assert frames[1] == marker and len(frames) == 2
    reply = json.loads(frames[0])
    assert reply["payload"] == {"blob": None, "size": len(marker)}
    assert reply["blobs"] == [["blob"]] and len(frames[0]) < 300


def test_descriptors_type_bytes() -> None:
    d = loads("""<service name="cam" version="1.0.0"><pattern>request-response</pattern>
      <operation name="snap"><param name="mask" type="bytes"/>
        <param name="tiles" type="list[bytes]" required="false"/></operation></service>""")
    check = d.validator()
    check("snap", {"mask": b"x", "tiles": [bytearray(b"y"), memoryview(b"z")]})
    with pytest.raises(robosoa.InvalidMessage, match="'mask': expected bytes, got str"):
        check("snap", {"mask": "eA=="})
    with pytest.raises(robosoa.InvalidMessage, match=r"'tiles\[0\]': expected bytes, got int"):
        check("snap", {"mask": b"", "tiles": [1]})


def test_bytes_cannot_have_a_default_or_cross_a_c_call() -> None:
    with pytest.raises(DescriptorError) as caught:
        loads("""<service name="cam" version="1.0.0"><pattern>request-response</pattern>
          <operation name="snap"><param name="mask" type="bytes" default="AA=="/>
            <return name="n" type="bytes"/></operation>
          <participant actor="provider" packaging="provider-library">
            <target language="c"/><implementation form="library" library="./libcam.so"/>
          </participant></service>""", source="cam.xml")
    assert [str(p) for p in caught.value.problems] == [
        "cam.xml:2: operation 'snap' parameter 'mask': type 'bytes' cannot have a default",
        "cam.xml:2: operation 'snap' 'mask': type 'bytes' cannot cross a C call "
        "(int, float, bool, string only)",
        "cam.xml:3: operation 'snap' 'n': type 'bytes' cannot cross a C call "
        "(int, float, bool, string only)",
    ]


def test_executables_read_and_write_bytes_as_base64() -> None:
    from robosoa.codegen import xmlcodec

    d = loads("""<service name="cam" version="1.0.0"><pattern>request-response</pattern>
      <operation name="snap"><param name="mask" type="bytes"/>
        <return name="n" type="list[bytes]"/></operation></service>""")
    returns = d.operation("snap").returns  # type: ignore[union-attr]
    assert b"<mask>AP8=</mask>" in xmlcodec.encode_request("cam", "snap", {"mask": b"\x00\xff"})
    document = b"<result><n><item>AP8=</item><item></item></n></result>"
    assert xmlcodec.decode_result(d, returns, document) == {"n": [b"\x00\xff", b""]}
    with pytest.raises(ValueError, match=r"n\[0\]: '!!' is not base64"):
        xmlcodec.decode_result(d, returns, b"<result><n><item>!!</item></n></result>")
