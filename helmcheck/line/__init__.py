"""The tester's side of a serial line, shared by the emulator and the live certifiers.

* :mod:`.transport` — opening a byte link (pty, serial device, TCP serial server, any pyserial
  URL) from a port spec; it re-exports the names of the modules below:
* :mod:`.port_spec` — parsing a ``--port`` value, the baud rates;
* :mod:`.linekind` — the line model a port gets (a pty or TCP on this host: clean; a UART: noisy);
* :mod:`.link` — the :class:`~helmcheck.line.link.Link` interface: polling, writing, blocking
  helpers;
* :mod:`.pty_link`, :mod:`.serial_link`, :mod:`.tcp_link` — the pseudo-terminal, the serial
  device (pyserial) and the TCP client and server links;
* :mod:`.pacer` — :class:`~helmcheck.line.pacer.LinePacer`, a UART's capacity at a baud rate;
* :mod:`.relay` — :class:`~helmcheck.line.relay.Relay`, the I/O thread between two links that
  reads both with one clock and forwards every byte in line (``helmcheck monitor --between``) or
  only reads (``--tap``);
* the line-fault relay, which spoils the line on purpose: :mod:`.impair_spec` (the ``--impair``
  text read into settings), :mod:`.impair` (the sans-IO schedule: what comes out when, and the
  notes), :mod:`.uart` (a bit stream re-sampled by a receiver at another baud),
  :mod:`.relaylog` (its wire log), :mod:`.faultrelay` (the ports, links and cuts around a
  :class:`~.relay.Relay` with the schedule as its stage: ``helmcheck relay``) and
  :mod:`.faultline` (:func:`~.faultline.impaired_line`, a vehicle behind a bad line for a test);
  :mod:`.faultdocs` makes its page, ``docs/line-faults.md``;
* :mod:`.linekind` — which line model a port gets (a pty, TCP to this host: clean; a UART, a
  serial server elsewhere: noisy);
* :mod:`.baudguess` — which common baud rate would make a garbled capture sentences (sans-IO);
* :mod:`.counters` — a serial port's error counters from the kernel (``TIOCGICOUNT``), or why
  there are none (a pty, a socket);
* :mod:`.recorder` — every event of a live run to the wire log (by the one wire-log writer,
  :mod:`helmcheck.grammar.wirelog`) and to the judges, identically;
* :mod:`.reopen` — a port that vanished (an adapter unplugged, a server that dropped its client),
  opened again under the same name once it is back, within the time a run waits for it;
* :mod:`.launcher` — start, watch and stop the implementation under test (``--exec CMD``);
* :mod:`.exec_port` — the tester's end of a port that a started implementation opens.

Nothing here judges: a driver above (:mod:`helmcheck.emulator`, :mod:`helmcheck.certify`)
decides what to send, the judges (:mod:`helmcheck.judge`) what it means.
"""
