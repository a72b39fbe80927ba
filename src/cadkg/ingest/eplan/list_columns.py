"""What the header cells of a connection list mean: EPLAN's Italian, German and English names
and the machine exports' ones (lower case, white space folded)."""

from __future__ import annotations

__all__ = ["ALIASES", "PAIRED", "PER_END"]

# Header text (lower case, white space folded) → meaning. Columns that occur twice
# (page, zone, pin) are origin first, destination second.
ALIASES: dict[str, str] = {
    "n. pagina": "page",
    "pagina": "page",
    "page": "page",
    "sheet": "page",
    "zona": "zone",
    "zone": "zone",
    "componente:pin": "pin",
    "component:pin": "pin",
    "device:pin": "pin",
    "betriebsmittel:anschluss": "pin",
    "componente: pin": "pin",
    "numero filo": "wire_number",
    "n. filo": "wire_number",
    "wire number": "wire_number",
    "wire no.": "wire_number",
    "verbindungsnummer": "wire_number",
    "sezione": "section",
    "sezione (mm²)": "section",
    "sezione (mm2)": "section",
    "section": "section",
    "cross-section": "section",
    "querschnitt": "section",
    "colore": "colour",
    "colour": "colour",
    "color": "colour",
    "farbe": "colour",
    "tipo": "potential_type",
    "tipo pot.": "potential_type",
    "potential type": "potential_type",
    "pot.": "potential_name",
    "nome pot.": "potential_name",
    "potential": "potential_name",
    "potential name": "potential_name",
    "l filo (m)": "length_m",
    "lunghezza (m)": "length_m",
    "length (m)": "length_m",
    "l filo (mm)": "length_mm",
    "lunghezza (mm)": "length_mm",
    "length (mm)": "length_mm",
    "lunghezza": "length_mm",
    "length": "length_mm",
    "traccia collegamenti": "duct_path",
    "percorso": "duct_path",
    "route": "duct_path",
    "terminazione origine": "origin_termination",
    "terminazione destinazione": "destination_termination",
    "chiave job": "job_key",
    "job key": "job_key",
    "nome cavo": "cable_name",
    "cable name": "cable_name",
    "lato fascettatura": "bundling_side",
    "bundling side": "bundling_side",
}
PAIRED = ("page", "zone", "pin")
# A header may tie its meaning to one end by a word after it ('Componente:pin origine',
# 'Lunghezza spelatura origine (mm)'). Only these meanings are read per end; the others
# (strip length, ferrule, marking) have no field in the record.
PER_END = {
    "termination": "termination",
    "terminazione": "termination",
    "direction": "direction",
    "direzione": "direction",
} | {alias: meaning for alias, meaning in ALIASES.items() if meaning in PAIRED}
