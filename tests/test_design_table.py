"""The answer rows of design.csv and the printed table: a pair's widest failing width and its
verdict with the vertical, from rows of summary.csv."""
from pipeline.design_table import design_rows, excess_text, failing_text, metadata_text, table_text


def _row(direction, verified, failing, overturns=False, vertical=None):
    return {"record": f"p@{direction}", "pair": "p", "column": "7.5x1.8", "column_kind": "block",
            "direction_deg": direction, "verified_width_m": verified, "widest_failing_width_m": failing,
            "overturns": overturns, "vertical_overturns": vertical, "width_m": 1.8,
            "verified_adequate": True, "max_theta_ratio": 0.5}


def test_a_pairs_widest_failing_width_is_one_above_its_governing_verified_width():
    # direction 0 governs (1.0 m); a sliver of direction 90 at 0.9 m fails no column of 1.0 m or wider
    d, = design_rows([_row(0, 1.0, None), _row(90, 0.8, 0.9)])
    assert d["direction_deg"] == 0 and d["verified_width_m"] == 1.0
    assert d["widest_failing_width_m"] is None
    # one at 1.1 m does: a column of 1.05 m fails in that direction
    d, = design_rows([_row(0, 1.0, None), _row(90, 0.8, 1.1)])
    assert d["widest_failing_width_m"] == 1.1


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


def test_excess_above_the_verified_width_is_shown_in_percent():
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


def test_the_printed_table_says_how_far_above_the_verified_width_a_column_fails():
    far = dict(_row(0, 0.593, 0.608), record="far", pair="far")
    tiny = dict(_row(0, 0.593, 0.593 * 1.00012), record="tiny", pair="tiny")
    none = dict(_row(0, 0.593, None), record="none", pair="none")
    text = table_text(design_rows([far, tiny, none]))
    lines = {line.split()[0]: line for line in text.splitlines()[2:]}
    assert "0.593 m  0.608 m (+2.5 %)" in lines["far"]
    # the two read equal to 3 decimals; the percentage says the failing one is above
    assert "0.593 m  0.593 m (+0.01 %)" in lines["tiny"]
    assert "0.593 m" in lines["none"] and "%" not in lines["none"]
    # the metres line up on the decimal point, the percentages start in one column
    assert lines["far"].index("(+") == lines["tiny"].index("(+")
    # none found: a dash where the metres end, and the verdict where the others have it
    assert lines["none"].split("0.593 m")[1].split()[0] == "-"
    assert lines["none"].rindex("-") == lines["far"].index(" m (") + 1
    assert lines["none"].index("yes") == lines["far"].index("yes")
