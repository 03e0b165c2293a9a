"""Float32 WAV files and windowed energy for the LV2 tests (lv2_test.py, jalv_test.py)."""
import struct


def write_wav(path, x, rate):
    """Mono float32 WAV (WAVE_FORMAT_IEEE_FLOAT)."""
    data = struct.pack("<%df" % len(x), *x)
    fmt = struct.pack("<HHIIHH", 3, 1, rate, rate * 4, 4, 32)
    with open(path, "wb") as f:
        f.write(b"RIFF" + struct.pack("<I", 4 + 8 + len(fmt) + 8 + len(data)) + b"WAVE")
        f.write(b"fmt " + struct.pack("<I", len(fmt)) + fmt)
        f.write(b"data" + struct.pack("<I", len(data)) + data)


def read_wav(path):
    """Float32 WAV -> (channels as lists, rate)."""
    with open(path, "rb") as f:
        b = f.read()
    assert b[:4] == b"RIFF" and b[8:12] == b"WAVE", path + ": not a WAV file"
    pos, fmt, data = 12, None, None
    while pos + 8 <= len(b):
        cid, size = b[pos:pos + 4], struct.unpack("<I", b[pos + 4:pos + 8])[0]
        body = b[pos + 8:pos + 8 + size]
        if cid == b"fmt ":
            fmt = struct.unpack("<HHIIHH", body[:16])
        elif cid == b"data":
            data = body
        pos += 8 + size + (size & 1)
    tag, channels, rate, _, _, bits = fmt
    assert tag in (3, 0xFFFE) and bits == 32, path + ": expected float32 samples"
    n = len(data) // 4
    x = struct.unpack("<%df" % n, data[:n * 4])
    return [list(x[c::channels]) for c in range(channels)], rate


def energy(chs, a, b):
    a, b = max(0, a), min(len(chs[0]), b)
    return sum(ch[i] * ch[i] for ch in chs for i in range(a, b))
