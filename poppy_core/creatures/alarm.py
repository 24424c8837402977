"""``AlarmSound``: the temperature monitor's alarm, a short tone played by the system's player.

pypot's creatures (poppy-torso and poppy-humanoid, ``primitives/safe.py``) ran
``subprocess.call([player, sound])`` with ``player='aplay'`` and a WAV shipped in the package,
at every check while a motor was too hot, blocking the primitive meanwhile. Here the player
runs beside the loop (never waited for), the tone is poppy's own (made here, no file shipped),
and a machine without audio says so once in the log instead of failing at every check.
"""

from __future__ import annotations

import io
import logging
import math
import shutil
import struct
import subprocess
import wave
from collections.abc import Sequence
from pathlib import Path

from poppy_core.files import write_file

logger = logging.getLogger(__name__)

PLAYERS: Sequence[str] = ("aplay", "paplay", "pw-play", "afplay")
"""Command-line players tried in this order when none is given (ALSA, PulseAudio, PipeWire,
macOS): each plays the WAV file given as its only argument."""

TONE_RATE_HZ = 16_000
TONE_NOTES_HZ: Sequence[float] = (880.0, 660.0, 880.0, 660.0)
TONE_NOTE_S = 0.12
TONE_VOLUME = 0.5


def alarm_tone() -> bytes:
    """poppy's alarm: four alternating notes, 0.5 s of 16-bit mono WAV."""
    samples = bytearray()
    per_note = int(TONE_RATE_HZ * TONE_NOTE_S)
    fade = per_note // 10  # ramps in and out: no click between notes
    for note in TONE_NOTES_HZ:
        for i in range(per_note):
            envelope = min(1.0, i / fade, (per_note - 1 - i) / fade)
            value = TONE_VOLUME * envelope * math.sin(2 * math.pi * note * i / TONE_RATE_HZ)
            samples += struct.pack("<h", int(value * 32767))
    out = io.BytesIO()
    with wave.open(out, "wb") as wav:
        wav.setnchannels(1)
        wav.setsampwidth(2)
        wav.setframerate(TONE_RATE_HZ)
        wav.writeframes(bytes(samples))
    return out.getvalue()


def default_sound() -> Path:
    """The alarm tone's WAV file in the user's cache folder, written the first time."""
    import platformdirs

    path = Path(platformdirs.user_cache_dir("poppy")) / "alarm.wav"
    tone = alarm_tone()
    if not path.is_file() or path.read_bytes() != tone:
        write_file(path, tone, replace=True, make_folder=True)
    return path


def find_player() -> str | None:
    """The first of ``PLAYERS`` on the PATH, or None."""
    for name in PLAYERS:
        found = shutil.which(name)
        if found:
            return found
    return None


class AlarmSound:
    """Plays ``sound`` with ``player`` at most once at a time, without waiting for it.

    Args:
        player: the program that plays a sound file (None: the first of ``PLAYERS`` found).
        sound: the WAV file to play (None: poppy's tone, see ``default_sound``).
    """

    def __init__(self, player: str | None = None, sound: str | Path | None = None) -> None:
        self.player = player
        self.sound = sound
        self.played = 0
        self._process: subprocess.Popen[bytes] | None = None
        self._warned = False

    def play(self) -> bool:
        """Start the sound (True), unless it still plays or cannot (False, said once)."""
        if self.playing():
            return False
        player = self.player or find_player()
        if player is None:
            self._warn_once(
                "no audio player found (%s): the temperature alarm is this log only",
                ", ".join(PLAYERS),
            )
            return False
        sound = Path(self.sound) if self.sound is not None else default_sound()
        try:
            self._process = subprocess.Popen(
                [player, str(sound)],
                stdin=subprocess.DEVNULL,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
            )
        except OSError as error:
            self._warn_once("the temperature alarm cannot start %s: %s", player, error)
            return False
        self.played += 1
        return True

    def playing(self) -> bool:
        """True while the last sound plays; a player that failed is said once."""
        if self._process is None:
            return False
        code = self._process.poll()
        if code is None:
            return True
        if code != 0:
            self._warn_once(
                "the temperature alarm did not play (%s exited with %d): no sound device?",
                self._process.args[0],  # type: ignore[index]
                code,
            )
        self._process = None
        return False

    def close(self) -> None:
        """Wait for a sound still playing (a short one) so no process is left behind."""
        if self._process is not None:
            try:
                self._process.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self._process.kill()
                self._process.wait()
            self._process = None

    def _warn_once(self, message: str, *args: object) -> None:
        if not self._warned:
            self._warned = True
            logger.warning(message, *args)
