"""The progress of a batch: a bar on a terminal, plain lines in a file or pipe, nothing with --quiet."""
import io

from ngcontact.output.progress_bar import BatchProgress


class Terminal(io.StringIO):
    def isatty(self):
        return True


def feed(progress, total=4):
    for k in range(total + 1):
        progress("ensemble", k, total)


def test_plain_lines_off_a_terminal_with_the_count_and_the_time_left():
    stream = io.StringIO()
    feed(BatchProgress(stream=stream))
    lines = stream.getvalue().splitlines()
    assert lines[0] == "ensemble: 4 independent solves"
    assert [line.split(",")[0] for line in lines[1:]] == [f"ensemble: {k}/4 finished" for k in range(1, 5)]
    assert all(line.endswith(" s left") and "about " in line for line in lines[1:])


def test_one_bar_on_a_terminal():
    stream = Terminal()
    feed(BatchProgress(stream=stream))
    text = stream.getvalue()
    assert "ensemble: 4/4" in text and "finished" not in text      # tqdm's bar, not the plain lines
    assert "\r" in text                                             # redrawn in place


def test_quiet_writes_nothing():
    stream = Terminal()
    feed(BatchProgress(quiet=True, stream=stream))
    assert stream.getvalue() == ""
