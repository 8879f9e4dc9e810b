"""age-image's core flags: --kinetics and --restore (written images, lost mask)."""

import re

import numpy as np
import pytest
from PIL import Image

from lightfade_addon import cli


@pytest.fixture()
def photo(tmp_path):
    rng = np.random.default_rng(1)
    y, x = np.mgrid[0:12, 0:16] / 12
    rgb = np.stack([0.6 + 0.3 * np.sin(4 * x), 0.5 + 0.3 * np.cos(3 * y), 0.45 + 0.2 * x], -1)
    rgb = np.clip(rgb + rng.normal(0, 0.02, rgb.shape), 0, 1)
    path = tmp_path / "old.png"
    Image.fromarray(np.rint(rgb * 255).astype(np.uint8), "RGB").save(path)
    return path


def read(path):
    return np.asarray(Image.open(path).convert("RGB"), np.float64) / 255


def run(*argv):
    return cli.main(["age-image", *map(str, argv)])


def test_kinetics_changes_the_result(photo, tmp_path):
    # bare wood (no colourant to unmix): the rate law shows in its yellowing alone, and
    # no unmixing table is built for a second (paper-kinetics) recipe
    for law in ("first-order", "paper"):
        assert run(photo, "--years", "3", "--lux", "1000", "--kinetics", law,
                   "--recipe", "bare-wood", "--out", tmp_path / law) == 0
    first, paper = read(tmp_path / "first-order" / "old_3y.png"), read(tmp_path / "paper" /
                                                                      "old_3y.png")
    assert np.abs(first - paper).max() > 2 / 255


def test_unknown_kinetics_is_refused(photo, capsys):
    try:
        code = run(photo, "--years", "1", "--kinetics", "zeroth")
    except SystemExit as exc:        # argparse's own exit
        code = exc.code
    assert code != 0 and "kinetics" in capsys.readouterr().err


def test_restore_writes_the_restored_image_and_the_lost_mask(photo, tmp_path, capsys):
    out = tmp_path / "restored"
    assert run(photo, "--years", "0", "2", "--lux", "1000", "--restore", "2", "--out", out) == 0
    restored, lost = read(out / "old_restored.png"), read(out / "old_lost.png")
    assert restored.shape == lost.shape == (12, 16, 3)
    assert set(np.unique(lost)) <= {0.0, 1.0}
    printed = capsys.readouterr().out
    # the count and share printed are the mask's
    count, share = re.search(r"(\d+) pixels \(([\d.]+)%\) lost", printed).groups()
    assert int(count) == np.count_nonzero(lost[..., 0])
    assert float(share) == round(100 * lost[..., 0].mean(), 1)
    # new again: the restored image is more colourful (less faded) than the photo
    np.testing.assert_allclose(read(out / "old_0y.png"), restored, atol=1 / 255)
    assert np.std(restored, axis=2).mean() > np.std(read(photo), axis=2).mean()


def test_restore_refuses_bad_years(photo, capsys):
    assert run(photo, "--years", "1", "--restore", "soon") != 0
    assert "--restore" in capsys.readouterr().err


def test_fastness_makes_one_dye_fugitive(photo, tmp_path):
    """--fastness yellow=1: the fabric's yellow fades far sooner, so colours go blue."""
    args = ("--years", "1", "--lux", "1000", "--recipe", "dyed-fabric")
    assert run(photo, *args, "--out", tmp_path / "matched") == 0
    assert run(photo, *args, "--fastness", "yellow=1", "--out", tmp_path / "fugitive") == 0
    matched = read(tmp_path / "matched" / "old_1y.png")
    fugitive = read(tmp_path / "fugitive" / "old_1y.png")
    # blue rises against red where the yellow went
    assert (fugitive[..., 2] - fugitive[..., 0]).mean() > (matched[..., 2] - matched[..., 0]
                                                           ).mean() + 0.02


@pytest.mark.parametrize("bad, says", [("yellow", "COLOURANT=CLASS"), ("yellow=9", "1-8"),
                                       ("green=2", "no colourant 'green'")])
def test_bad_fastness_is_refused(photo, capsys, bad, says):
    try:
        code = run(photo, "--years", "1", "--recipe", "dyed-fabric", "--fastness", bad)
    except SystemExit as exc:        # argparse's own exit
        code = exc.code
    assert code != 0 and says in capsys.readouterr().err
