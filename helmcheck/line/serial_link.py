"""The serial-device link (:class:`SerialLink`): a device path or pyserial URL, opened 8N1 at a
baud rate through pyserial.
"""

from __future__ import annotations

import errno
import os
import select
import time
from typing import Optional

from .link import Link, LinkClosed, LinkEvent, _write_fd
from .port_spec import _URL_RE


class SerialLink(Link):
    """A serial device or pyserial URL, opened 8N1 at ``baud`` (RH-FRM-9)."""

    def __init__(self, spec: str, baud: int = 19200):
        import serial  # pyserial; imported here so pty/TCP users do not pay for it

        self.baud = baud
        self.name = spec
        self.description = f"serial {spec} {baud} 8N1"
        kwargs = dict(baudrate=baud, bytesize=serial.EIGHTBITS, parity=serial.PARITY_NONE,
                      stopbits=serial.STOPBITS_ONE, timeout=0, write_timeout=0)
        if _URL_RE.match(spec):
            self.ser = serial.serial_for_url(spec, **kwargs)
        else:
            self.ser = serial.Serial(spec, **kwargs)
        self._empty = 0
        try:
            self._fd: Optional[int] = self.ser.fileno()
        except Exception:  # noqa: BLE001 - URL handlers without a descriptor (loop://)
            self._fd = None

    def fileno(self) -> int:
        if self._fd is None:
            raise OSError(errno.ENOTSUP, f"{self.name}: not selectable")
        return self._fd

    def wait_readable(self, timeout: Optional[float]) -> bool:
        if self._fd is None:  # no descriptor: poll gently
            time.sleep(min(timeout if timeout is not None else 0.01, 0.01))
            return True
        return super().wait_readable(timeout)

    def poll(self, max_bytes: int = 65536) -> list[LinkEvent]:
        import serial

        try:
            if self._fd is not None:
                # A tty read with VMIN=0 returns b"" when nothing is there: that is not an
                # end of file. A device that goes away raises EIO/ENXIO instead.
                try:
                    data = os.read(self._fd, max_bytes)
                except (BlockingIOError, InterruptedError):
                    data = b""
                except OSError as e:
                    raise LinkClosed(errno.EIO, f"{self.name}: {e.strerror or e}") from None
            else:
                data = self.ser.read(min(self.ser.in_waiting, max_bytes))
        except serial.SerialException as e:
            raise LinkClosed(errno.EIO, f"{self.name}: {e}") from None
        if data:
            self._empty = 0
            return [LinkEvent("data", data)]
        if self._fd is not None and select.select([self._fd], [], [], 0)[0]:
            self._empty += 1  # readable yet nothing to read: a hung-up line
            if self._empty > 1000:
                raise LinkClosed(errno.EIO, f"{self.name}: line hung up")
        return []

    def write_some(self, data: bytes) -> int:
        import serial

        if self._fd is not None:
            return _write_fd(self._fd, data)
        try:
            return self.ser.write(data) or 0
        except serial.SerialTimeoutException:
            return 0

    def close(self) -> None:
        try:
            self.ser.close()
        except Exception:  # noqa: BLE001
            pass
