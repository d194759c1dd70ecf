"""The answer rows of design.csv and the printed table: a pair's widest failing width and its
verdict with the vertical, from rows of summary.csv."""
from pipeline.reports.answer import excess_text, failing_text, metadata_text, table_text
from pipeline.reports.design_table import design_rows


def _row(direction, design, failing, overturns=False, vertical=None, search=None):
    return {"record": f"p@{direction}", "pair": "p", "column": "7.5x1.8", "column_kind": "block",
            "direction_deg": direction, "design_width_m": design, "widest_failing_width_m": failing,
            "overturns": overturns, "vertical_overturns": vertical, "width_m": 1.8,
            "design_adequate": True, "max_theta_ratio": 0.5, "search_width_m": search,
            "check_runs": 1500}


def test_a_pairs_widest_failing_width_is_one_above_its_governing_search_width():
    # direction 0 governs (design 1.0 m, search 0.95 m); a sliver of direction 90 at 0.9 m lies
    # below the governing search width: no failure of the design's direction
    d, = design_rows([_row(0, 1.0, None, search=0.95), _row(90, 0.8, 0.9, search=0.7)])
    assert d["direction_deg"] == 0 and d["design_width_m"] == 1.0
    assert d["widest_failing_width_m"] is None and d["search_width_m"] == 0.95
    # one at 0.99 m (the governing direction's own, just below its design width) is reported
    d, = design_rows([_row(0, 1.0, 0.99, search=0.95), _row(90, 0.8, None, search=0.7)])
    assert d["widest_failing_width_m"] == 0.99 < d["design_width_m"]


def test_the_verdict_with_the_vertical_covers_every_direction():
    d, = design_rows([_row(0, 1.0, None, vertical=False), _row(90, 0.8, None, vertical=True)])
    assert d["survives_vertical"] is False and d["survives"] is True
    d, = design_rows([_row(0, 1.0, None), _row(90, 0.8, None)])
    assert d["survives_vertical"] is None  # no vertical: blank, and no column printed
    assert "with vertical" not in table_text([d])


def test_metadata_line_of_a_peer_record():
    row = {"peer_rsn": 77.0, "peer_event": "San Fernando", "peer_year": 1971.0,
           "peer_station": "Pacoima Dam (upper left abut)", "peer_magnitude": 6.61,
           "peer_mechanism": "Reverse", "peer_rrup_km": 1.81, "peer_vs30_m_s": 2016.13,
           "peer_tp_s": 1.638, "velocity_tp_s": 1.6381}
    assert metadata_text(row) == ("RSN77 San Fernando 1971, Pacoima Dam (upper left abut): M6.61 Reverse, "
                                  "Rrup 1.81 km, Vs30 2016.13 m/s, velocity pulse Tp 1.64 s (PEER), "
                                  "1.64 s (here)")
    assert metadata_text({"record": "x"}) is None


def test_excess_above_the_search_width_is_shown_in_percent():
    # far above: 0.608 over 0.593 is +2.53 %; a tenth of a percent step resolves it
    assert excess_text(0.608, 0.593) == "+2.5 %"
    assert excess_text(0.75, 0.6) == "+25 %"
    assert excess_text(0.5945, 0.593) == "+0.25 %"
    # a hair above: 0.01 % (6e-5 m on 0.593 m) must not read "+0.0 %", and less reads "<+0.01 %"
    assert excess_text(0.593 * 1.0002, 0.593) == "+0.02 %"
    assert excess_text(0.593 * 1.00001, 0.593) == "<+0.01 %"
    # none found, nothing to compare with, or not above: no percentage
    assert excess_text(None, 0.593) is None and excess_text(0.6, None) is None
    assert excess_text(0.593, 0.593) is None
    assert failing_text(0.608, 0.593) == "0.608 m (+2.5 %)"
    assert failing_text(0.608, 0.593, unit="") == "0.608 (+2.5 %)"
    assert failing_text(0.608, None) == "0.608 m" and failing_text(None, 0.593) is None


def test_the_printed_table_says_how_far_the_design_width_lies_above_the_search():
    far = dict(_row(0, 0.608, 0.6079, search=0.593), record="far", pair="far")
    tiny = dict(_row(0, 0.593 * 1.00012, 0.593 * 1.0001, search=0.593), record="tiny", pair="tiny")
    none = dict(_row(0, 0.593, None, search=0.593), record="none", pair="none")
    text = table_text(design_rows([far, tiny, none]))
    lines = {line.split()[0]: line for line in text.splitlines()[2:] if line}
    assert "0.608 m  0.593 m (+2.5 %)" in lines["far"]
    # the two read equal to 3 decimals; the percentage says the design width is above the search's
    assert "0.593 m  0.593 m (+0.01 %)" in lines["tiny"]
    assert "0.593 m  0.593 m" in lines["none"] and "%" not in lines["none"]
    # the metres line up on the decimal point, the percentages start in one column
    assert lines["far"].index("(+") == lines["tiny"].index("(+")
    assert lines["none"].index("yes") == lines["far"].index("yes")
    # the fine print says what was tested above the width, with the docs on slivers
    assert "the check ran 1500 widths per record" in text and "docs/slivers.md" in text


def test_eq31_safe_island_and_the_suite_answer():
    """Eq. 31 below the design width is flagged and counted; a column on a safe island reads NO;
    the run ends with the width covering every record."""
    base = dict(_row(0, 1.0, None, search=1.0), eq31_width_m=0.8, eq31_width_overturns=True)
    rows = [dict(base, record="a", pair="a"),                                   # Eq. 31 below, overturns
            dict(base, record="b", pair="b", design_width_m=2.2, search_width_m=2.0,
                 design_adequate=False, eq31_width_m=2.5, eq31_width_overturns=False),
            dict(base, record="c", pair="c", eq31_width_m=1.2, eq31_width_overturns=False)]
    d = design_rows(rows)
    assert [r["eq31_below_design"] for r in d] == [True, False, False]
    assert [r["verdict"] for r in d] == ["survives", "NO: safe island", "survives"]
    text = table_text(d)
    lines = {line.split()[0]: line for line in text.splitlines()[2:5]}
    assert "0.800 m BELOW, overturns" in lines["a"] and "BELOW" not in lines["c"]
    assert lines["b"].rstrip().endswith("NO: safe island")
    assert ("Suite, column 7.5x1.8: the design width covering all 3 record(s) is 2.200 m (set by b); "
            "as it stands (1.800 m) it FAILS: 0 record(s) overturn it, 1 leave it on a safe island") in text
    assert "Eq. 31 is below the design width on 1 of 3 record(s); a column of Eq. 31's width overturns under 1 of them." in text
    # a level: a column that stands but exceeds R fails it, said as such (it does not overturn)
    lv = design_rows([dict(base, record="a", pair="a", design_limit=0.4)])[0]
    assert lv["survives"] is False and lv["verdict"] == "NO: exceeds level"
    assert "for max theta/alpha <= 0.4" in table_text([lv])
    assert table_text([lv]).splitlines()[2].rstrip().endswith("NO: exceeds 0.4")
    # one that overturns reads NO, as without a level
    over = design_rows([dict(base, record="a", pair="a", design_limit=0.4, overturns=True)])[0]
    assert over["verdict"] == "NO"


def test_the_motion_that_governs_is_marked_where_it_is_the_vertical():
    """A design width set by the response with the vertical reads ``(vertical)`` beside it, in the
    printed table and the page; one set by the horizontal motion alone carries no mark."""
    from pipeline.reports.answer import table_cells

    vert = dict(_row(0, 1.553, None, search=1.5), design_governed_by="with vertical",
                record="v", pair="v")
    hor = dict(_row(0, 1.431, None, search=1.431), design_governed_by="horizontal",
               record="h", pair="h")
    d = {r["record"]: r for r in design_rows([vert, hor])}
    assert d["v"]["design_governed_by"] == "with vertical"
    assert table_cells(d["v"])[5] == "1.553 m (vertical)"
    assert table_cells(d["h"])[5] == "1.431 m"
    text = table_text([d["v"], d["h"]])
    assert "1.553 m (vertical)" in text and "1.431 m (vertical)" not in text


def test_a_levels_overturning_width_is_the_widest_over_directions_and_in_the_fine_print():
    """Under --limit: design.csv's overturning_width_m is the widest over a pair's directions (the
    governing direction's need not be it), the printed table's widths stay the level's, and the
    fine print says the design width is at least the overturning one; blank without a level."""
    rows = [dict(_row(0, 1.0, None, search=0.95), design_limit=0.5, overturning_width_m=0.7),
            dict(_row(90, 0.9, None, search=0.85), design_limit=0.5, overturning_width_m=0.8)]
    d, = design_rows(rows)
    assert d["overturning_width_m"] == 0.8 and d["design_width_m"] == 1.0
    text = table_text([d])
    assert "1.000 m for max theta/alpha <= 0.5" in text
    assert "the verge (no margin) is 0.800 m" in text and "is at least the verge" in text
    plain, = design_rows([_row(0, 1.0, None, search=0.95)])
    assert plain["overturning_width_m"] is None
    assert "overturning design width" not in table_text([plain])
