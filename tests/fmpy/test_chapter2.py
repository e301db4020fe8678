"""Chapter 2's claims table (docs/chapter2-claims.md) is what `make chapter2-claims` writes from the
FMUs of this build, and the exact wall keeps the dissertation's main claim of chapter 2."""

import re

from actuator_fmus import chapter2


def test_the_claims_page_is_generated_from_these_fmus():
    table = chapter2.rows()
    assert chapter2.PAGE.read_text() == chapter2.page(table), \
        "docs/chapter2-claims.md is stale: run make chapter2-claims"
    claims = {row[0]: row for row in table}
    # Section 2.4: more pre-strain, more net work (A < B < C). The walls as written miss it; the
    # exact wall holds it.
    work = next(row for claim, row in claims.items() if claim.startswith("More pre-strain"))
    assert work[2].endswith("fails") and work[3].endswith("holds")
    # Every figure from 2.6 to 2.14 has its row.
    for figure in range(6, 15):
        assert any(re.search(rf"Fig(s)?\. 2\.{figure}\b", claim) for claim in claims), f"Fig. 2.{figure}"
    # Fig. 2.9: Table 2.1's rubber is the literature's C1 = 161 kPa, C2 = 39 kPa.
    rubber = next(row for claim, row in claims.items() if "(Fig. 2.9)" in claim)
    assert rubber[3] == "C1 = 161, C2 = 39 kPa"
