"""'Send to laser' as a user clicks it: the port sim:// (the built-in GRBL emulator), Send,
progress advancing, Pause (the emulator holds), Resume, Abort (beam off, job ended), and
ports that cannot be used answered with a one-line message on the page. Screenshots go to
test-artifacts/."""

from __future__ import annotations

import pytest

from tests.chromium import ARTIFACTS
from tests.studio.browser_page import settle

pytestmark = pytest.mark.slow

STATUS = "document.getElementById('send-status')"
ACKED = "document.getElementById('send-progress').value"


def player_line(page) -> int:
    """The G-code line the laser panel's player shows."""
    return int(page.inner_text("#laser-player [data-role=number]").split("/")[0].replace(",", "").strip())


def state(page) -> str:
    return page.eval_on_selector("#send-status", "e => e.dataset.state")


def test_send_pause_resume_abort_on_the_emulator(page):
    page.click("nav .tab[data-tab=laser]")
    settle(page, extra="document.getElementById('laser-time').textContent.includes('estimated')")
    assert page.is_enabled("#send") and not page.is_enabled("#pause") and not page.is_enabled("#abort")
    # The emulator at twice a real machine's speed (default sim:// runs ten times faster):
    # slow enough to pause a 12 s job by hand.
    page.fill("#port", "sim://?speed=2")
    # Every status the page shows while streaming, to check it never says the machine idles.
    page.evaluate("""window.sendTexts = []; new MutationObserver(() => window.sendTexts.push(
        document.getElementById('send-status').textContent)).observe(document.getElementById('send-status'),
        {childList: true, characterData: true, subtree: true})""")
    page.click("#send")
    page.wait_for_function(f"{STATUS}.dataset.state === 'streaming' && {ACKED} > 0")
    first = page.evaluate(ACKED)
    page.wait_for_function(f"{ACKED} > {first} + 5")  # progress advances while it streams
    total = page.evaluate("document.getElementById('send-progress').max")
    assert first < page.evaluate(ACKED) < total and total > 100
    # The estimate's line count is the lines Send streams.
    assert f"· {total} lines ·" in page.inner_text("#laser-time"), (total, page.inner_text("#laser-time"))
    assert not page.is_enabled("#send") and page.is_enabled("#pause") and not page.is_enabled("#resume")
    # The laser preview's head follows the job: the player shows the line acknowledged last.
    shown = player_line(page)
    page.wait_for_function(f"{ACKED} > {page.evaluate(ACKED)} + 5")
    assert 1 < shown < player_line(page) < page.evaluate("document.getElementById('send-progress').max") + 10
    page.screenshot(path=str(ARTIFACTS / "studio-send-1-streaming.png"))

    page.click("#pause")
    # The emulator decelerates (Hold:1) and stops (Hold:0); no line is acknowledged meanwhile.
    page.wait_for_function(f"{STATUS}.dataset.state === 'paused' && {STATUS}.textContent.includes('Hold:0')")
    held = page.evaluate(ACKED)
    page.wait_for_timeout(700)
    assert page.evaluate(ACKED) == held and state(page) == "paused"
    assert page.is_enabled("#resume") and not page.is_enabled("#pause")
    page.screenshot(path=str(ARTIFACTS / "studio-send-2-paused.png"))

    page.click("#resume")
    page.wait_for_function(f"{STATUS}.dataset.state === 'streaming' && {ACKED} > {held}")
    streaming = [t for t in page.evaluate("window.sendTexts") if t.startswith("streaming")]
    machine = {t.split("machine ")[1].split(" ")[0] for t in streaming if "machine " in t}
    assert "Run" in machine and machine <= {"Run", "Hold:0", "Hold:1"}, streaming  # never the connect's Idle
    page.click("#abort")
    page.wait_for_function(f"{STATUS}.dataset.state === 'aborted'")
    text = page.inner_text("#send-status")
    assert "stopped on request" in text and "beam off" in text, text
    assert page.evaluate(ACKED) < total
    assert page.is_enabled("#send") and not page.is_enabled("#abort") and not page.is_enabled("#resume")
    page.screenshot(path=str(ARTIFACTS / "studio-send-3-aborted.png"))


def test_send_to_a_port_that_cannot_be_used(page):
    page.click("nav .tab[data-tab=laser]")
    page.fill("#port", "/dev/ttyUSB97")
    page.click("#send")
    page.wait_for_function(f"{STATUS}.dataset.state === 'failed'")
    text = page.inner_text("#send-status")
    assert "/dev/ttyUSB97 does not exist" in text and "onestroke ports" in text, text
    assert page.is_enabled("#send")
    page.screenshot(path=str(ARTIFACTS / "studio-send-4-missing-port.png"))
    # A controller whose receive buffer is smaller than a line of the job: refused at once,
    # nothing sent (character counting used to wait for room forever, "connecting").
    page.fill("#port", "sim://?rx=10")
    page.click("#send")
    page.wait_for_function(f"{STATUS}.dataset.state === 'failed' && {STATUS}.textContent.includes('rx=10')")
    text = page.inner_text("#send-status")
    assert "10-byte receive buffer" in text and "nothing was sent" in text, text
    assert page.is_enabled("#send") and not page.is_enabled("#abort")
    # Another pyserial URL (it could reach the network) is refused before anything opens.
    page.fill("#port", "socket://192.0.2.1:23")
    page.click("#send")
    page.wait_for_function(f"{STATUS}.dataset.state === 'error'")
    text = page.inner_text("#send-status")
    assert "give a serial device" in text and "sim://" in text, text
    assert "Traceback" not in page.content()
