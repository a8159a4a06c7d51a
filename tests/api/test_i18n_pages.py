"""Languages and units of the screens (issue 17 items 1-2, design.md §9.9).

The Chinese texts are the manual's (seed 001 §4.2/4.3: 测量工件, 测量棱边, 设置棱边, 匹配测量头,
NC 启动, 测量头未接通), the German ones Operate's. Inch: 1 inch = 25.4 mm exactly (ISO 31), typed
on a screen, read back in mm through the JSON API (its contract stays mm and English).
"""

from __future__ import annotations

import re

import pytest
from babel.messages.pofile import read_po
from hmi_testdata import BLOCK_TOP_Z, PROBE_LENGTH, TEST_SCENARIO

from app.i18n import LOCALE_DIR
from app.web.language import choose, from_accept_language

HTMX = {"HX-Request": "true"}
HOLE = TEST_SCENARIO["workpiece"]["features"][1]
PART_T = TEST_SCENARIO["workpiece"]["pose"]["trans"]
HOLE_MCS = (PART_T[0] + HOLE["center"][0], PART_T[1] + HOLE["center"][1])
INCH = 25.4


# --- which language ------------------------------------------------------------------------------

@pytest.mark.parametrize("header, expected", [
    ("zh-CN,zh;q=0.9,en;q=0.8", "zh"), ("de-DE,de;q=0.9", "de"), ("fr-FR, de;q=0.5, en;q=0.7", "en"),
    ("fr", None), ("", None), ("de;q=0, zh;q=0.1", "zh")])
def test_accept_language_by_quality(header, expected):
    assert from_accept_language(header) == expected


def test_order_query_cookie_setting_browser():
    assert choose("de", "zh", "en", "zh") == "de"
    assert choose(None, "zh", "de", "de") == "zh"
    assert choose(None, None, "de", "zh") == "de"
    assert choose(None, None, "auto", "zh-CN") == "zh"
    assert choose("xx", None, "auto", None) == "en"


def test_query_lang_is_remembered_by_a_cookie(client):
    first = client.get("/jog?lang=zh")
    assert '<html lang="zh">' in first.text and "hmi_lang=zh" in first.headers["set-cookie"]
    assert '<html lang="zh">' in client.get("/jog").text          # the cookie
    client.cookies.clear()
    assert '<html lang="en">' in client.get("/jog").text


def test_accept_language_and_the_setting(client):
    assert "Werkstück messen" in client.get("/jog", headers={"Accept-Language": "de-DE,de;q=0.9"}).text
    assert client.put("/api/settings", json={"language": "zh"}).status_code == 200
    text = client.get("/jog", headers={"Accept-Language": "de"}).text
    assert "测量工件" in text and "Werkstück messen" not in text


def test_the_api_stays_english(client):
    client.cookies.set("hmi_lang", "zh")
    answer = client.put("/api/offsets/G54", json={"trans": {"Y": "abc"}}, headers={"Accept-Language": "zh-CN"})
    assert answer.status_code in (400, 422)
    error = answer.json()["error"]
    assert error["field"] == "trans.Y" and re.search(r"[A-Za-z]", error["message"])
    assert not re.search(r"[\u4e00-\u9fff]", error["message"])


# --- the manual's texts on the JOG and measuring screens --------------------------------------------

def test_jog_screen_in_chinese_and_german(client):
    zh = client.get("/jog?lang=zh").text
    for text in ("测量工件", "测量刀具", "零点偏移", "NC 启动", "复位", "无报警。", "实际值 WCS"):
        assert text in zh, text
    de = client.get("/jog?lang=de").text
    for text in ("Werkstück messen", "Werkzeug messen", "Nullpunktverschiebung", "NC-Start", "Keine Alarme.",
                 "Istwert WKS"):
        assert text in de, text


def test_measuring_menus_and_screen_in_chinese(client):
    menu = client.get("/measure/workpiece?lang=zh").text
    for text in ("测量棱边 &gt;", "测量转角 &gt;", "测量槽/钻孔 &gt;", "测量轴颈 &gt;", "矫正平面", "匹配测量头 &gt;", "返回"):
        assert text in menu, text
    edge = client.get("/measure/workpiece/edge?lang=zh").text
    assert "设置棱边" in edge and "校准棱边" in edge and "2 棱边间距" in edge
    task = client.get("/measure/workpiece/edge/set?lang=zh").text
    assert "仅测量" in task and "额定值" in task and "方向" in task


def test_measuring_screen_in_german_with_an_error_in_the_operators_words(client):
    client.cookies.set("hmi_lang", "de")
    answer = client.post("/measure/task/hole.1/start", headers=HTMX,
                         data={"target": "G54", "diameter": "abc", "probe_angle": "0"})
    assert "Durchmesser ca.: Zahl eingeben" in answer.text
    assert "diameter" not in answer.text.split('id="message"')[1]


def test_alarm_in_the_screens_language_and_english_in_the_api(client):
    client.post("/api/machine/tool", json={"tool": 9})
    for target in ({"Z": 0.0}, {"X": 100.0, "Y": 100.0}, {"Z": BLOCK_TOP_Z - 10.0 + PROBE_LENGTH}):
        client.post("/api/machine/goto", json={**target, "coords": "MCS"})
    client.cookies.set("hmi_lang", "zh")
    answer = client.post("/measure/task/edge.align/start", headers=HTMX,
                         data={"axis": "Y", "direction": "-", "reference_axis": "X"})
    assert "61301" in answer.text and "测量头未接通" in answer.text
    alarms = client.get("/api/machine").json()["alarms"]
    assert any(a["code"] == 61301 and a["text"] == "Probe not switched" for a in alarms)
    assert "测量头未接通" in client.get("/jog").text          # the JOG alarm pane and the header


def test_numbers_and_dates_in_german(client):
    client.put("/api/offsets/G54", json={"trans": {"X": 12.5}})
    text = client.get("/offsets?lang=de").text
    assert 'value="12,500"' in text
    assert re.search(r">-?\d+,\d{3}<", client.get("/jog?lang=de").text)


def test_no_developer_jargon_on_operator_screens(client):
    for path in ("/settings", "/probes", "/tool-probes", "/jog", "/measure/workpiece/edge/set"):
        shown = re.sub(r"<[^>]*>", " ", client.get(path).text)       # what the operator reads
        assert "_JM_I[" not in shown and "spec §" not in shown and "_PRNUM" not in shown, path
    for path in ("/probes", "/tool-probes"):
        assert re.search(r'id="message"[^>]*>\s*None\s*<', client.get(path).text) is None
    cell = client.post("/offsets/G54/trans.Y", data={"value": "abc"}, headers=HTMX).text
    assert "translation Y: enter a number" in cell and "trans.Y:" not in cell and "is not a number" not in cell
    cell = client.post("/offsets/G54/trans.Y?lang=zh", data={"value": "abc"}, headers=HTMX).text
    assert "平移 Y：请输入数字" in cell
    saved = client.post("/probes/1", data={"ball_diameter": "x"}, headers=HTMX)
    assert "ball_diameter" not in saved.text.split('role="alert"')[1][:120]


# --- units --------------------------------------------------------------------------------------------

@pytest.fixture
def inch(client):
    assert client.put("/api/settings", json={"units": "inch"}).json()["units"] == "inch"
    return client


def test_inch_typed_into_the_offset_table_is_stored_as_mm(inch):
    answer = inch.post("/offsets/G54/trans.X", data={"value": "1.0000"}, headers=HTMX)
    assert answer.status_code == 200
    assert inch.get("/api/offsets/G54").json()["trans"]["X"] == pytest.approx(INCH, abs=1e-12)
    assert 'value="1.0000"' in answer.text
    inch.post("/offsets/G54/trans.Y", data={"value": "-0.1"}, headers=HTMX)
    assert inch.get("/api/offsets/G54").json()["trans"]["Y"] == pytest.approx(-2.54, abs=1e-12)
    inch.post("/offsets/G54/rot.Z", data={"value": "1.5"}, headers=HTMX)        # degrees stay degrees
    assert inch.get("/api/offsets/G54").json()["rot"]["Z"] == pytest.approx(1.5)


def test_an_untouched_inch_cell_keeps_the_stored_mm(inch):
    inch.put("/api/offsets/G54", json={"trans": {"X": 10.0}})
    shown = f"{10.0 / INCH:.4f}"                        # 0.3937: not exact in inch
    inch.post("/offsets/G54/trans.X", data={"value": shown}, headers=HTMX)
    assert inch.get("/api/offsets/G54").json()["trans"]["X"] == 10.0


def test_inch_typed_into_the_tool_list_and_the_probe_data(inch):
    tool = inch.get("/api/tools").json()[0]
    inch.post(f"/tools/{tool['t']}/length", data={"value": "4"}, headers=HTMX)
    assert inch.get(f"/api/tools/{tool['t']}").json()["length"] == pytest.approx(4 * INCH)
    record = inch.get("/api/probes/1").json()
    form = {"ball_diameter": "0.25", "effective_diameter": "0", "tool": str(record.get("tool") or "")}
    inch.post("/probes/1", data=form, headers=HTMX)
    assert inch.get("/api/probes/1").json()["ball_diameter"] == pytest.approx(0.25 * INCH)


def test_inch_on_a_measuring_screen_writes_the_right_mm(inch):
    inch.post("/api/machine/tool", json={"tool": 9})
    inch.post("/api/machine/activate", json={"offset": "G54"})
    for target in ({"Z": 0.0}, {"X": HOLE_MCS[0] + 1.0, "Y": HOLE_MCS[1] - 2.0},
                   {"Z": BLOCK_TOP_Z - 10.0 + PROBE_LENGTH}):
        inch.post("/api/machine/goto", json={**target, "coords": "MCS"})
    diameter_inch = HOLE["diameter"] / INCH
    answer = inch.post("/measure/task/hole.1/start", headers=HTMX, data={
        "target": "G54", "diameter": f"{diameter_inch:.4f}", "probe_angle": "0",
        "setpoint.X": "1", "setpoint.Y": "-0.5"})
    assert 'id="task-result"' in answer.text
    g54 = inch.get("/api/offsets/G54").json()["trans"]
    # the hole's centre is the setpoint: G54 = centre (MCS) − setpoint (mm)
    assert g54["X"] == pytest.approx(HOLE_MCS[0] - 1 * INCH, abs=1e-6)
    assert g54["Y"] == pytest.approx(HOLE_MCS[1] + 0.5 * INCH, abs=1e-6)
    assert f'data-result="Diameter">{HOLE["diameter"] / INCH:.4f}<' in answer.text
    assert "inch" in answer.text


def test_the_measuring_screen_shows_lengths_in_inch(inch):
    text = inch.get("/measure/workpiece/pocket/hole1").text
    assert ">inch<" in text and ">mm<" not in text.split('id="screen"')[1].split('id="vsoftkeys"')[0]


# --- the catalogues ------------------------------------------------------------------------------------

@pytest.mark.parametrize("lang", ["de", "zh"])
def test_catalogue_placeholders_match(lang):
    with (LOCALE_DIR / lang / "LC_MESSAGES" / "messages.po").open("rb") as fp:
        catalog = read_po(fp, locale=lang)
    names = re.compile(r"%\((\w+)\)s")
    wrong = [m.id for m in catalog if m.id and m.string and sorted(names.findall(m.id)) != sorted(names.findall(m.string))]
    assert not wrong


def test_every_text_of_the_screens_is_translated():
    """Operator texts in the operator's language: each text the code, the templates and the data
    tables give the screens (alarm remedies included) has a German and a Chinese translation
    (after new texts: python scripts/i18n.py extract && python scripts/i18n.py update, then translate)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("i18n_tool", LOCALE_DIR.parents[1] / "scripts" / "i18n.py")
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    texts = [m.id for m in tool.collect() if m.id]
    for lang in ("de", "zh"):
        with (LOCALE_DIR / lang / "LC_MESSAGES" / "messages.po").open("rb") as fp:
            translated = {m.id for m in read_po(fp, locale=lang) if m.id and m.string}
        missing = [t for t in texts if t not in translated]
        assert not missing, f"{lang}: {len(missing)} texts without a translation, e.g. {missing[:3]}"


def _form_as_shown(page: str) -> dict:
    """The settings form as the browser would post it untouched (inputs, checked boxes, selected options)."""
    form = {}
    for tag in re.findall(r"<input [^>]*>", page):
        name, value = re.search(r'name="([^"]+)"', tag), re.search(r'value="([^"]*)"', tag)
        if name and ('type="checkbox"' not in tag or " checked" in tag):
            form[name.group(1)] = value.group(1) if value and 'type="checkbox"' not in tag else "on"
    for name, options in re.findall(r'<select [^>]*name="([^"]+)"[^>]*>(.*?)</select>', page, re.S):
        chosen = re.search(r'<option value="([^"]*)" selected', options)
        if chosen:
            form[name] = chosen.group(1)
    return form


def test_inch_typed_into_the_settings_form(inch):
    form = _form_as_shown(inch.get("/settings").text)
    assert form["cal_ring_diameter"] == "0" and form["units"] == "inch"
    form["cal_ring_diameter"] = "1"                 # inch; measuring_path (50 mm) stays as shown
    answer = inch.post("/settings", data=form, headers=HTMX)
    assert answer.status_code == 200 and "Settings saved" in answer.text
    saved = inch.get("/api/settings").json()
    assert saved["cal_ring_diameter"] == pytest.approx(INCH, abs=1e-12)
    assert saved["measuring_path"] == 50.0 and saved["units"] == "inch"
