"""The answer rows of design.csv and the printed table: a pair's widest failing width and its
verdict with the vertical, from rows of summary.csv."""
from pipeline.design_table import design_rows, metadata_text, table_text


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
