"""Decodes a Sample stream's messages straight into NumPy arrays.

A SampleBatch's columns are packed repeated doubles (or floats), or raw
little-endian `bytes` columns (RawColumns, COLUMN_ENCODING_RAW); either way
each column is one contiguous little-endian run of bytes: numpy.frombuffer
reads it (one memcpy per column) without creating a Python float per value,
which the protobuf message API would. The StreamHeader (small, first message only) goes through
the generated sampler_pb2. Pure functions.
"""

import numpy as np

from sfcsampler.errors import DataLossError
from sfcsampler.v1 import sampler_pb2

_COLUMN_NAMES = (None, "u", "v", "x", "y", "z", "nx", "ny", "nz", "density", "curve_position")


def _varint(buf, pos):
    result = shift = 0
    while True:
        if pos >= len(buf):
            raise DataLossError(15, "a truncated varint in a Sample message")
        b = buf[pos]
        pos += 1
        result |= (b & 0x7F) << shift
        if not b & 0x80:
            return result, pos
        shift += 7


def encode_varint(value):
    out = bytearray()
    while True:
        byte = value & 0x7F
        value >>= 7
        if value:
            out.append(byte | 0x80)
        else:
            out.append(byte)
            return bytes(out)


def fields(buf):
    """Yields (field number, wire type, value) where value is an int or a memoryview."""
    pos, end = 0, len(buf)
    while pos < end:
        tag, pos = _varint(buf, pos)
        number, wire_type = tag >> 3, tag & 7
        if wire_type == 0:
            value, pos = _varint(buf, pos)
        elif wire_type == 1:
            value, pos = buf[pos:pos + 8], pos + 8
        elif wire_type == 2:
            length, pos = _varint(buf, pos)
            value, pos = buf[pos:pos + length], pos + length
        elif wire_type == 5:
            value, pos = buf[pos:pos + 4], pos + 4
        else:
            raise DataLossError(15, f"unexpected wire type {wire_type} in a Sample message")
        if pos > end:
            raise DataLossError(15, "a truncated field in a Sample message")
        yield number, wire_type, value


def _columns(buf, dtype):
    pieces = {}
    for number, _, value in fields(buf):
        if 1 <= number <= 10:  # packed or not, the bytes are the values
            pieces.setdefault(_COLUMN_NAMES[number], []).append(np.frombuffer(value, dtype=dtype))
    # Copies: writable arrays that do not keep the whole message alive.
    return {
        name: parts[0].copy() if len(parts) == 1 else np.concatenate(parts)
        for name, parts in pieces.items()
    }


def _raw_columns(buf):
    """RawColumns: each column one run of little-endian values, float64 or
    float32 as its precision field (11) says; numpy.frombuffer reads each."""
    views, precision = {}, 0
    for number, wire_type, value in fields(buf):
        if 1 <= number <= 10 and wire_type == 2:
            views[_COLUMN_NAMES[number]] = value
        elif number == 11 and wire_type == 0:
            precision = value
    if precision not in (0, 1):
        raise DataLossError(15, f"raw columns of unknown precision {precision}")
    dtype = np.dtype("<f4" if precision == 1 else "<f8")
    out = {}
    for name, view in views.items():
        if len(view) % dtype.itemsize:
            raise DataLossError(
                15, f"a raw column {name} of {len(view)} bytes is not whole {dtype} values")
        out[name] = np.frombuffer(view, dtype=dtype).copy()  # writable, and frees the message
    return out


def _batch(buf, requested):
    first_index, size, index, columns, model_columns = 0, 0, [], {}, {}
    for number, _, value in fields(buf):
        if number == 1:
            first_index = value
        elif number == 2:
            index.append(np.frombuffer(value, dtype="<u8"))
        elif number == 3:
            size = value
        elif number == 4:
            columns = _columns(value, np.dtype("<f8"))
        elif number == 5:
            columns = _columns(value, np.dtype("<f4"))
        elif number == 8:
            columns = _raw_columns(value)
        elif number in (6, 7):  # face, triangle: packed fixed32
            name = "face" if number == 6 else "triangle"
            model_columns.setdefault(name, []).append(np.frombuffer(value, dtype="<u4"))
    for name, parts in model_columns.items():
        columns[name] = np.concatenate(parts) if len(parts) > 1 else parts[0].copy()
    # `size` is just a number on the wire: the columns, checked first, bound what it may make
    # us allocate (the request always has one).
    out = {}
    for name in requested:
        column = columns.get(name)
        if size and (column is None or len(column) != size):
            raise DataLossError(15, f"a batch of {size} samples has a bad or missing {name} column")
        if column is not None:
            out[name] = column
    if index:
        index = np.concatenate(index) if len(index) > 1 else index[0].copy()
        if len(index) != size:
            raise DataLossError(15, f"a batch has {len(index)} indices for {size} samples")
    else:
        index = np.arange(first_index, first_index + size, dtype=np.uint64)
    return {"index": index, **out}


def decode_response(raw, requested):
    """(StreamHeader or None, dict of columns) of one serialized SampleResponse.

    `requested` names the columns the request asked for; a column that
    is missing or of the wrong length is DataLossError.
    """
    buf = memoryview(raw)
    header, batch = None, {"index": np.empty(0, dtype=np.uint64)}
    for number, wire_type, value in fields(buf):
        if number == 1 and wire_type == 2:
            header = sampler_pb2.StreamHeader.FromString(bytes(value))
        elif number == 2 and wire_type == 2:
            batch = _batch(value, requested)
    return header, batch


def message_dict(message):
    """A protobuf message as a dict with its proto field names (numbers stay numbers)."""
    out = {}
    for field in message.DESCRIPTOR.fields:
        value = getattr(message, field.name)
        if field.label == field.LABEL_REPEATED:
            value = [message_dict(v) if hasattr(v, "DESCRIPTOR") else v for v in value]
        elif field.message_type is not None:
            value = message_dict(value)
        out[field.name] = value
    return out
