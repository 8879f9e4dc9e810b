"""The progress protocol: ``progress(fraction, message)`` and its command-line adapter."""

import io

from lightfade_addon.progress import ProgressBar, console_after, report, scaled, silent


class TestProgressBar:
    def test_on_a_terminal_it_redraws_one_line(self):
        buf = io.StringIO()
        bar = ProgressBar("grid", stream=buf, width=10, tty=True)
        bar(0.0, "start")
        bar(0.5, "half")
        bar.close()
        text = buf.getvalue()
        assert text.count("\r") == 2 and text.endswith("\n") and text.count("\n") == 1
        assert "[#####.....]  50%  half" in text

    def test_a_shorter_line_blanks_the_rest_of_the_longer_one(self):
        buf = io.StringIO()
        bar = ProgressBar("", stream=buf, width=4, tty=True)
        bar(0.0, "a long message")
        bar(1.0, "ok")
        last = buf.getvalue().split("\r")[-1]
        assert last.startswith("[####] 100%  ok") and len(last) == len("[....]   0%  a long message")

    def test_elsewhere_it_writes_a_line_per_message(self):
        buf = io.StringIO()
        with ProgressBar("grid", stream=buf, tty=False) as bar:
            for f in (0.0, 0.1, 0.2):
                bar(f, "building")
            bar(1.0, "ready")
        assert buf.getvalue().splitlines() == ["grid   0%  building", "grid 100%  ready"]

    def test_fractions_are_clamped(self):
        buf = io.StringIO()
        bar = ProgressBar("", stream=buf, tty=False)
        bar(-1.0, "before")
        bar(7.0, "after")
        bar(float("nan"), "nan")
        assert [line.split("%")[0].strip() for line in buf.getvalue().splitlines()] == [
            "0", "100", "0"]


class TestHelpers:
    def test_scaled_maps_onto_part_of_the_job(self):
        seen = []
        inner = scaled(lambda f, m: seen.append((round(f, 12), m)), 0.6, 0.9)
        inner(0.0, "a")
        inner(0.5, "b")
        inner(1.0, "c")
        assert seen == [(0.6, "a"), (0.75, "b"), (0.9, "c")]

    def test_scaled_twice_composes(self):
        seen = []
        scaled(scaled(lambda f, m: seen.append(f), 0.5, 1.0), 0.0, 0.5)(1.0, "")
        assert seen == [0.75]

    def test_none_is_silent(self):
        assert report(None) is silent and silent(0.5, "x") is None
        scaled(None, 0.0, 1.0)(0.5, "nobody listens")
        own = [].append
        assert report(own) is own


class TestConsoleAfter:
    def _clocked(self, progress=None):
        out, now = io.StringIO(), [0.0]
        say = console_after(progress, 2.0, "Age", out, clock=lambda: now[0])
        return say, out, now

    def test_quiet_for_two_seconds_then_a_line_per_new_message(self):
        seen = []
        say, out, now = self._clocked(lambda f, m: seen.append(m))
        say(0.1, "table")
        now[0] = 1.9
        say(0.2, "still quick")
        assert out.getvalue() == ""
        now[0] = 2.0
        say(0.5, "group")
        say(0.6, "group")
        now[0] = 3.0
        say(1.0, "done")
        assert out.getvalue().splitlines() == ["Age:  50%  group (2.0 s)",
                                               "Age: 100%  done (3.0 s)"]
        assert seen == ["table", "still quick", "group", "group", "done"]

    def test_a_progress_that_prints_itself_is_not_doubled(self):
        bar = ProgressBar("x", stream=io.StringIO(), tty=False)
        assert console_after(bar, 0.0) is bar
