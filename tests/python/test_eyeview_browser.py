"""eyeview in a real browser (Debian's chromium, headless, through its chromedriver): the page loads and shows the
render, moving a slider changes the image and the session layer holds the edit, a NaN typed into a field is one
message while the render goes on, and a killed server leaves the page with a message and its last image."""
import shutil
import time

import pytest

eyerender = pytest.importorskip("eyerender", reason="the eyerender package is not installed (make python)")
from pxr import Sdf  # noqa: E402
from selenium import webdriver  # noqa: E402
from selenium.webdriver.chrome.service import Service  # noqa: E402
from selenium.webdriver.common.by import By  # noqa: E402
from selenium.webdriver.common.keys import Keys  # noqa: E402
from selenium.webdriver.support.ui import WebDriverWait  # noqa: E402

from eyeview_fixture import RunningView, eye_stage  # noqa: E402

CHROMIUM, CHROMEDRIVER = shutil.which("chromium"), shutil.which("chromedriver")
# As root in a container: no sandbox, no GPU, nothing reaching out to the network (scripts/install_deps.sh).
CHROMIUM_FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                  "--disable-background-networking", "--disable-component-update", "--disable-sync",
                  "--disable-dev-shm-usage", "--window-size=900,700")

# The sum of the shown image's pixels (same origin, so the canvas may read them), with the version it shows.
IMAGE_SUM = """
const img = document.getElementById('frame');
if (!img.complete || !img.naturalWidth) return null;
const canvas = document.createElement('canvas');
canvas.width = img.naturalWidth; canvas.height = img.naturalHeight;
const context = canvas.getContext('2d');
context.drawImage(img, 0, 0);
const data = context.getImageData(0, 0, canvas.width, canvas.height).data;
let sum = 0;
for (let i = 0; i < data.length; i += 4) sum += data[i] + data[i + 1] + data[i + 2];
return [Number(img.dataset.version), sum];
"""


@pytest.fixture
def browser(tmp_path):
    assert CHROMIUM and CHROMEDRIVER, "chromium and chromium-driver are installed by scripts/install_deps.sh"
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for flag in CHROMIUM_FLAGS + (f"--user-data-dir={tmp_path / 'chromium-profile'}",):
        options.add_argument(flag)
    driver = webdriver.Chrome(service=Service(executable_path=CHROMEDRIVER), options=options)
    driver.set_page_load_timeout(30)
    yield driver
    driver.quit()


@pytest.fixture
def view(tmp_path):
    running = RunningView(eye_stage(tmp_path / "eye.usda"), tmp_path / "look.usda", width=96)
    yield running
    running.close()


def shown_image(driver, after_version=-1, timeout=30):
    """(version, pixel sum) of the image the page shows, once it shows one newer than `after_version`."""
    def newer(d):
        shown = d.execute_script(IMAGE_SUM)
        return shown if shown and shown[0] > after_version else None
    return WebDriverWait(driver, timeout).until(newer)


def status_samples(driver):
    text = driver.find_element(By.ID, "status").text  # "96 x 96, 12 / 4096 spp, ..."
    return int(text.split(", ")[1].split(" /")[0]) if " spp" in text else 0


def message(driver):
    return driver.find_element(By.ID, "message").text


def test_the_page_shows_the_render_and_a_moved_slider_changes_the_image_and_the_session_layer(browser, view,
                                                                                               tmp_path):
    browser.get(view.url)
    WebDriverWait(browser, 30).until(lambda d: status_samples(d) >= 4)
    version, before = shown_image(browser)
    assert before > 0
    slider = browser.find_element(By.ID, "ctl-pupil")
    slider.send_keys(Keys.END)  # the widest pupil: the keyboard moves a range input and fires its change event
    WebDriverWait(browser, 30).until(
        lambda d: view.viewer.editor.controls["pupil"].value > 14 and status_samples(d) >= 2)
    shown_image(browser, after_version=version + 1)  # a new image after the edit
    WebDriverWait(browser, 30).until(lambda d: shown_image(d)[1] < 0.95 * before)  # a black pupil over the iris
    browser.find_element(By.ID, "save").click()
    WebDriverWait(browser, 30).until(lambda d: "saved the session layer" in message(d))
    layer = Sdf.Layer.FindOrOpen(str(tmp_path / "look.usda"))
    assert layer.GetAttributeAtPath("/World/Eye.eye:pupilDiameter").default > 14


def test_a_nan_typed_into_a_field_is_one_message_and_the_render_goes_on(browser, view):
    browser.get(view.url)
    WebDriverWait(browser, 30).until(lambda d: status_samples(d) >= 2)
    field = browser.find_element(By.ID, "num-pupil")
    field.send_keys(Keys.CONTROL, "a")  # select what the field shows, and type over it
    field.send_keys("NaN", Keys.ENTER)
    WebDriverWait(browser, 30).until(lambda d: "not a finite number" in message(d))
    samples = status_samples(browser)
    WebDriverWait(browser, 30).until(lambda d: status_samples(d) > samples)  # not restarted, not stopped
    assert view.viewer.editor.layer.GetAttributeAtPath("/World/Eye.eye:pupilDiameter") is None


def test_a_killed_server_leaves_a_message_and_the_last_image(browser, view):
    browser.get(view.url)
    version, _ = shown_image(browser)
    view.close()
    WebDriverWait(browser, 30).until(lambda d: "not answering" in message(d))
    time.sleep(0.5)
    shown = browser.execute_script(IMAGE_SUM)
    assert shown is not None and shown[0] >= version and shown[1] > 0
