"""The softkeys and screen titles that have a counterpart in the manual use the manual's Chinese
term (issue 28 item 7): each row names the seed line (001_*.txt, the Chinese SW 6.3 manual) where
the term stands under or beside the softkey. The catalogue is read through the product's own
``gettext`` in Chinese, and the measuring menu shows the terms."""

from __future__ import annotations

import pytest

from app.i18n import gettext, using

# (the product's English text, the manual's Chinese term, seed line)
MANUAL_TERMS = (
    ("Measure workpiece", "测量工件", 4471),
    ("Calibrate probe", "匹配测量头", 4471),          # workpiece menu: (测量工件) (匹配测量头) (半径)
    ("Radius", "半径", 4471),
    ("Length", "长度", 4521),
    ("Measure tool", "测量刀具", 6441),               # tool menu: (测量刀具) (匹配测量头 >)
    ("Calibrate probe >", "匹配测量头 >", 6381),
    ("Diameter", "直径", 6378),
    ("Orient plane", "矫正平面", 6038),               # §4.3.6 矫正平面 (the product had 校准平面)
    ("Set edge", "设置棱边", 5208),
    ("Align edge", "校准棱边", 5210),
    ("Distance 2 edges", "2 棱边间距", 5212),
    ("Measure corner", "测量转角", 4861),
    ("Measure pocket/hole", "测量槽/钻孔", 4863),
    ("Measure spigot", "测量轴颈", 4872),
    ("Right-angled corner", "直角", 2480),
    ("Any corner", "任意角", 2511),
    ("1 hole", "1 个钻孔", 5612),
    ("1 circular spigot", "1 个圆轴颈", 5683),
    ("<< Back", "<< 返回", 6384),
)


@pytest.mark.parametrize("english, term, line", MANUAL_TERMS, ids=[row[0] for row in MANUAL_TERMS])
def test_the_chinese_softkey_is_the_manuals_term(english, term, line):
    with using("zh"):
        assert gettext(english) == term, f"seed 001 line {line}: {term}"


def test_the_menus_show_the_manuals_terms(client):
    workpiece = client.get("/measure/workpiece?lang=zh").text
    assert "矫正平面" in workpiece and "匹配测量头" in workpiece and "校准平面" not in workpiece
    tool = client.get("/measure/tool?lang=zh").text
    assert "匹配测量头" in tool and "校正测量头" not in tool
