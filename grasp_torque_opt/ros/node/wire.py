# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
The joint states' and the commands' bytes on the wire, by layouts rclpy read or wrote.

At a thousand joint states a second, rclpy's conversions are a large share of the
node's path: ``deserialize_message`` of a joint state, and ``publish`` of a message
(which converts it before it sends the bytes). A driver sends the same
joint state every cycle but for its stamp and values, and the node publishes the same
command but for its values; rclpy reads or writes one, and the others follow its
layout:

- :class:`JointStateLayout`: a joint state rclpy deserialized is walked by CDR's
  alignment (little-endian only) to where its frame, names and values are; when all
  of them are what rclpy read, byte for byte, its bytes are the layout. A later message
  is read without rclpy only when it has the same length and the same bytes in the
  frame, the names and every length and count (all but the stamp, the values and the
  padding, which rclpy leaves unset): rclpy would read it the same way (the tests hold
  the two to each other). Any other message goes through rclpy, and may become the
  layout.
- :class:`Serialized`: a message of the command's shape is serialized by rclpy with
  marked values; where the marks are found, exactly once, each command's bytes are
  that template with its values (and stamp) written in, and the template is held to
  rclpy's deserialization of a test value when it is made.

Written here, not taken from a library: rclpy offers no cheaper conversion, and these
are the package's own two messages on its hottest path.
"""

from __future__ import annotations

from array import array
import struct
from typing import Any

from builtin_interfaces.msg import Time
from rclpy.serialization import deserialize_message, serialize_message

#: The stamp's place in a serialized message with a std_msgs/Header first: after
#: the 4 bytes of the CDR encapsulation, int32 seconds and uint32 nanoseconds.
STAMP = struct.Struct('<iI')
STAMP_AT = 4
#: A CDR length or count.
U32 = struct.Struct('<I')
#: The encapsulation this module reads and writes: CDR, little-endian.
CDR_LE = b'\x00\x01'


def _only(data: bytes, block: bytes) -> int:
    """Return where ``block`` is in ``data``, if exactly once; else -1."""
    at = data.find(block)
    if at < 0 or data.find(block, at + 1) >= 0:
        return -1
    return at


def marked(msg: Any, field: str, n: int) -> tuple[bytes, tuple[int, int]]:
    """
    Serialize ``msg`` by rclpy with ``n`` marked float64 values in ``field``; find them.

    The marks are tiny distinct doubles no reading gives; they are set on ``msg``.
    Returns the bytes and the marks' (start, end) in them.

    Raises:
        ValueError: the bytes are not little-endian CDR, or the marks are not found
            exactly once.
    """
    setattr(msg, field, array('d', [1.0e-300 * (3 + 7 * i) for i in range(n)]))
    raw = serialize_message(msg)
    block = getattr(msg, field).tobytes()
    at = _only(raw, block) if n else -1
    if raw[:2] != CDR_LE or at < 0:
        raise ValueError(f'the marks of {field} are not found once in little-endian CDR')
    return raw, (at, at + len(block))


def _joint_state_walk(data: bytes) -> tuple[list, list, list] | None:
    """
    Return where a little-endian CDR sensor_msgs/JointState's fields are, or None.

    By CDR's alignment (from the end of the encapsulation): strings and counts at 4,
    float64 values at 8. Returns (the ranges whose bytes fix the layout: the frame's
    and names' lengths and bytes, the counts; the strings' (start, end) without their
    NUL; the position, velocity and effort values' (start, end), None where empty).
    The padding between fields and the bytes after the last are in no range: rclpy
    leaves them unset, so they differ between messages.
    """
    n, p = len(data), STAMP_AT + STAMP.size

    def align(at: int, k: int) -> int:
        return at + (-(at - STAMP_AT) % k)

    def string(at: int) -> int:
        at = align(at, 4)
        if at + 4 > n:
            return -1
        length = U32.unpack_from(data, at)[0]
        if not 1 <= length <= n - at - 4:
            return -1
        keep.append((at, at + 4 + length))
        strings.append((at + 4, at + 3 + length))
        return at + 4 + length

    keep: list[tuple[int, int]] = []
    strings: list[tuple[int, int]] = []
    p = string(p)
    if p < 0 or align(p, 4) + 4 > n:
        return None
    p = align(p, 4)
    count = U32.unpack_from(data, p)[0]
    keep.append((p, p + 4))
    p += 4
    if count > n:
        return None
    for _ in range(count):
        p = string(p)
        if p < 0:
            return None
    spans = []
    for _ in range(3):
        p = align(p, 4)
        if p + 4 > n:
            return None
        count = U32.unpack_from(data, p)[0]
        keep.append((p, p + 4))
        p += 4
        if count == 0:
            spans.append(None)
            continue
        p = align(p, 8)
        if p + 8 * count > n:
            return None
        spans.append((p, p + 8 * count))
        p += 8 * count
    return keep, strings, spans


def _merged(ranges: list[tuple[int, int]]) -> list[tuple[int, int]]:
    """Return byte ranges (in order) with those that touch merged."""
    out: list[tuple[int, int]] = []
    for a, b in ranges:
        if out and out[-1][1] == a:
            out[-1] = (out[-1][0], b)
        else:
            out.append((a, b))
    return out


class JointStateLayout:
    """
    Read sensor_msgs/JointState bytes of the last layout rclpy read (module docstring).

    Attributes:
        read_here: messages read by the layout; ``by_rclpy``: the others.
    """

    def __init__(self) -> None:
        """Start with no layout."""
        self._layout: tuple | None = None
        self.read_here = 0
        self.by_rclpy = 0

    def read(self, data: bytes) -> tuple[Time, list[str], array, array] | None:
        """
        Return (stamp, names, positions, efforts) of a message of the layout, else None.

        The names are the layout's own list (the same object each time: not to be
        changed); positions and efforts are ``array('d')``, as rclpy gives them.
        """
        layout = self._layout
        if layout is None or len(data) != layout[0]:
            return None
        size, constant, names, pos, eff = layout
        for a, b, ref in constant:
            if data[a:b] != ref:
                return None
        sec, nanosec = STAMP.unpack_from(data, STAMP_AT)
        positions = array('d')
        positions.frombytes(data[pos[0]:pos[1]])
        efforts = array('d')
        if eff is not None:
            efforts.frombytes(data[eff[0]:eff[1]])
        self.read_here += 1
        return Time(sec=sec, nanosec=nanosec), names, positions, efforts

    def learn(self, data: bytes, msg: Any) -> bool:
        """
        Take the layout of ``data``, whose reading by rclpy is ``msg``, if they agree.

        The fields are found by CDR's alignment (:func:`_joint_state_walk`); the layout is
        taken only when the stamp, the frame, every name and every value found there are
        ``msg``'s, byte for byte. Else the layout is dropped (every message goes through
        rclpy until one is learnt).
        """
        self.by_rclpy += 1
        self._layout = None
        walked = _joint_state_walk(data) if data[:2] == CDR_LE else None
        if walked is None or len(msg.position) == 0:
            return False
        keep, strings, spans = walked
        stamp = msg.header.stamp
        texts = [data[a:b] for a, b in strings]
        values = [b'' if span is None else data[span[0]:span[1]] for span in spans]
        if (STAMP.unpack_from(data, STAMP_AT) != (stamp.sec, stamp.nanosec)
                or texts != [t.encode() for t in (msg.header.frame_id, *msg.name)]
                or values != [array('d', v).tobytes() for v in (
                    msg.position, msg.velocity, msg.effort)]):
            return False
        constant = tuple((a, b, data[a:b]) for a, b in _merged(keep))
        self._layout = (len(data), constant, list(msg.name), spans[0], spans[2])
        return True


class Serialized:
    """
    A command message's bytes with its values (and stamp) written in (module docstring).

    Args:
        msg: the message, of its final shape (names, frame), whose ``field`` holds
            ``n`` float64 values; its stamp is written in when ``stamped``.
        field: the float64 array written each time (``data``, ``effort``).
        n: its length.
        stamped: the message starts with a std_msgs/Header whose stamp is written.

    Raises:
        ValueError: the values' place cannot be found once, or the template does not
            read back as the message (never expected: then the caller publishes
            messages).
    """

    def __init__(self, msg: Any, field: str, n: int, stamped: bool = False) -> None:
        """Serialize ``msg`` (its ``field`` and stamp set here) with marks; check a test value."""
        self._n, self._stamped = n, stamped
        raw, span = marked(msg, field, n)
        if stamped and span[0] < STAMP_AT + STAMP.size:
            raise ValueError('the command layout cannot be learnt')
        self._head, self._tail = raw[:span[0]], raw[span[1]:]
        test = array('d', [0.25 * (i + 1) for i in range(n)])
        stamp = Time(sec=12, nanosec=34)
        setattr(msg, field, test)
        if stamped:
            msg.header.stamp = stamp
        if deserialize_message(self.write(test, stamp), type(msg)) != msg:
            raise ValueError('the command layout does not read back')

    def write(self, values: array | bytes, stamp: Any = None) -> bytes:
        """Return the message's bytes with ``values`` (n float64) and ``stamp`` written in."""
        body = values if isinstance(values, bytes) else values.tobytes()
        if len(body) != 8 * self._n:
            raise ValueError(f'{len(body) // 8} values for a command of {self._n}')
        if not self._stamped:
            return self._head + body + self._tail
        head = self._head
        return (head[:STAMP_AT] + STAMP.pack(stamp.sec, stamp.nanosec)
                + head[STAMP_AT + STAMP.size:] + body + self._tail)
