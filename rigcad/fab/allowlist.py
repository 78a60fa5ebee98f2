"""Which PrusaSlicer settings rigcad hands to the slicer: an allow-list of the settings that shape
a print, so a printer file, a user's .ini or a vendor bundle written by someone else can never run
a program, write or read a file, or reach a network host through the slicer.

The names are PrusaSlicer 2.5's FFF options (``prusa-slicer --save`` and ``--help-fff``, the
configuration block of its G-code, and the keys of the vendor bundles it ships). Each setting is
in :data:`ALLOWED` (by what it shapes), in :data:`REFUSED` (with why), or unknown. Sources:

* the printer file's ``slicer.overrides``: an allowed key passes; any other is refused with a
  ProfileError naming the key, its file:line and why;
* a vendor bundle's presets or a user's flat .ini: an allowed key passes; a refused key is left out
  when its value is harmless (see :data:`REFUSED`: an empty ``post_process = `` line, as every
  PrusaSlicer export writes; a vendor's ``output_filename_format`` naming a file in the output
  folder, which rigcad never uses because it names every output itself), refused otherwise; an
  unknown key (another slicer's, such as SuperSlicer's in some bundles) is left out, as
  PrusaSlicer 2.5 itself ignores it;
* the configuration rigcad writes for one piece (rigcad.fab.slicer): checked again as a whole.

Every value is one line of text without control characters (PrusaSlicer's own ``\\n`` escapes
stay text), and the settings with a physical meaning in :data:`RANGES` must lie in their range.

Custom G-code (``start_gcode`` and the other ``*_gcode`` settings) is allowed: it is G-code for the
printer, not a command for this machine. PrusaSlicer expands it with its macro language
(placeholders, arithmetic, conditions: no file or process access) and writes it into the G-code
file; nothing runs here. A print host may act on some lines (OctoPrint's ``@`` commands, which
PrusaSlicer's own Artillery bundle uses), but only as its owner configured it. Literal temperature
commands in it (M104/M109 nozzle, M140/M190 bed) are held to the same ranges as the settings.
"""

from __future__ import annotations

import re

from rigcad.errors import FabricationError, ProfileError

#: Settings that shape a print, grouped by what they shape (PrusaSlicer 2.5 FFF option names).
ALLOWED: dict[str, frozenset[str]] = {k: frozenset(v.split()) for k, v in {
    "layers and perimeters": """layer_height first_layer_height min_layer_height max_layer_height
        variable_layer_height perimeters extra_perimeters top_solid_layers bottom_solid_layers solid_layers
        top_solid_min_thickness bottom_solid_min_thickness solid_min_thickness ensure_vertical_shell_thickness
        external_perimeters_first seam_position thin_walls thick_bridges overhangs perimeter_generator
        wall_distribution_count wall_transition_angle wall_transition_filter_deviation wall_transition_length
        min_bead_width min_feature_size avoid_crossing_perimeters avoid_crossing_perimeters_max_detour
        spiral_vase interface_shells fuzzy_skin fuzzy_skin_point_dist fuzzy_skin_thickness""",
    "infill": """fill_density fill_pattern fill_angle top_fill_pattern bottom_fill_pattern infill_anchor
        infill_anchor_max infill_every_layers infill_first infill_only_where_needed infill_overlap
        solid_infill_below_area solid_infill_every_layers bridge_angle gap_fill_enabled ironing ironing_flowrate
        ironing_spacing ironing_type""",
    "skirt and brim": """skirts skirt_distance skirt_height min_skirt_length draft_shield brim_type brim_width
        brim_separation""",
    "support and raft": """support_material support_material_auto support_material_angle
        support_material_bottom_contact_distance support_material_bottom_interface_layers
        support_material_buildplate_only support_material_closing_radius support_material_contact_distance
        support_material_enforce_layers support_material_interface_contact_loops support_material_interface_layers
        support_material_interface_pattern support_material_interface_spacing support_material_pattern
        support_material_spacing support_material_style support_material_synchronize_layers
        support_material_threshold support_material_with_sheath support_material_xy_spacing dont_support_bridges
        raft_contact_distance raft_expansion raft_first_layer_density raft_first_layer_expansion raft_layers""",
    "speed": """perimeter_speed small_perimeter_speed external_perimeter_speed infill_speed solid_infill_speed
        top_solid_infill_speed support_material_speed support_material_interface_speed bridge_speed gap_fill_speed
        ironing_speed travel_speed travel_speed_z first_layer_speed first_layer_speed_over_raft max_print_speed
        max_volumetric_speed max_volumetric_extrusion_rate_slope_negative
        max_volumetric_extrusion_rate_slope_positive""",
    "acceleration and machine limits": """default_acceleration perimeter_acceleration infill_acceleration
        bridge_acceleration first_layer_acceleration first_layer_acceleration_over_raft machine_limits_usage
        machine_max_acceleration_e machine_max_acceleration_extruding machine_max_acceleration_retracting
        machine_max_acceleration_travel machine_max_acceleration_x machine_max_acceleration_y
        machine_max_acceleration_z machine_max_feedrate_e machine_max_feedrate_x machine_max_feedrate_y
        machine_max_feedrate_z machine_max_jerk_e machine_max_jerk_x machine_max_jerk_y machine_max_jerk_z
        machine_min_extruding_rate machine_min_travel_rate silent_mode""",
    "extrusion width and flow": """extrusion_width first_layer_extrusion_width perimeter_extrusion_width
        external_perimeter_extrusion_width infill_extrusion_width solid_infill_extrusion_width
        top_infill_extrusion_width support_material_extrusion_width extrusion_multiplier bridge_flow_ratio
        xy_size_compensation elefant_foot_compensation slice_closing_radius slicing_mode resolution
        gcode_resolution mmu_segmented_region_max_width clip_multipart_objects""",
    "temperature and cooling": """temperature first_layer_temperature bed_temperature first_layer_bed_temperature
        standby_temperature_delta cooling fan_always_on fan_below_layer_time min_fan_speed max_fan_speed
        bridge_fan_speed disable_fan_first_layers full_fan_speed_layer slowdown_below_layer_time min_print_speed""",
    "retraction and wipe": """retract_length retract_lift retract_lift_above retract_lift_below retract_speed
        deretract_speed retract_restart_extra retract_before_travel retract_before_wipe retract_layer_change
        retract_length_toolchange retract_restart_extra_toolchange only_retract_when_crossing_perimeters wipe
        use_firmware_retraction filament_retract_length filament_retract_lift filament_retract_lift_above
        filament_retract_lift_below filament_retract_speed filament_deretract_speed filament_retract_restart_extra
        filament_retract_before_travel filament_retract_before_wipe filament_retract_layer_change filament_wipe""",
    "bed and nozzle geometry": """printer_technology bed_shape max_print_height nozzle_diameter z_offset
        extruder_offset extruder_clearance_height extruder_clearance_radius complete_objects duplicate_distance""",
    "filament": """filament_diameter filament_density filament_type filament_soluble filament_cost
        filament_spool_weight filament_colour filament_max_volumetric_speed filament_vendor""",
    "extruders, multi-material and wipe tower": """extruder extruder_colour perimeter_extruder infill_extruder
        solid_infill_extruder support_material_extruder support_material_interface_extruder
        single_extruder_multi_material single_extruder_multi_material_priming ooze_prevention wipe_tower
        wipe_tower_x wipe_tower_y wipe_tower_width wipe_tower_rotation_angle wipe_tower_brim_width
        wipe_tower_bridging wipe_tower_no_sparse_layers wiping_volumes_extruders wiping_volumes_matrix
        wipe_into_infill wipe_into_objects cooling_tube_length cooling_tube_retraction parking_pos_retraction
        extra_loading_move high_current_on_filament_swap filament_cooling_final_speed filament_cooling_initial_speed
        filament_cooling_moves filament_load_time filament_loading_speed filament_loading_speed_start
        filament_minimal_purge_on_wipe_tower filament_ramming_parameters filament_toolchange_delay
        filament_unload_time filament_unloading_speed filament_unloading_speed_start""",
    "custom G-code (for the printer; never run here)": """start_gcode end_gcode before_layer_gcode layer_gcode
        after_layer_gcode toolchange_gcode between_objects_gcode color_change_gcode pause_print_gcode
        template_custom_gcode start_filament_gcode end_filament_gcode""",
    "the G-code's form": """gcode_flavor gcode_comments gcode_label_objects extrusion_axis use_relative_e_distances
        use_volumetric_e remaining_times thumbnails thumbnails_format colorprint_heights""",
    "preset names and notes (text the G-code tests)": """print_settings_id printer_settings_id
        filament_settings_id physical_printer_settings_id printer_model printer_variant printer_vendor
        default_print_profile default_filament_profile notes printer_notes filament_notes""",
}.items()}
#: Every allowed key.
ALLOWED_KEYS: frozenset[str] = frozenset().union(*ALLOWED.values())


def _empty(value: str) -> bool:
    return value.strip().strip('"') == ""


def _file_name_only(value: str) -> bool:
    """An output name template that stays in the output folder: no separator, no parent step."""
    return "/" not in value and "\\" not in value and ".." not in value


#: Settings never handed to PrusaSlicer -> (why, when a preset's value is harmless and is left out).
REFUSED: dict[str, tuple[str, object]] = {
    "post_process": ("names scripts PrusaSlicer runs on this machine after exporting the G-code", _empty),
    "output_filename_format": ("names the G-code file PrusaSlicer writes; rigcad names every output itself",
                               _file_name_only),
    "gcode_substitutions": ("rewrites the finished G-code past every check of its settings", _empty),
    "bed_custom_texture": ("names a file on this machine for PrusaSlicer to read", _empty),
    "bed_custom_model": ("names a file on this machine for PrusaSlicer to read", _empty),
    "threads": ("sets how this machine runs PrusaSlicer, not the print; rigcad chooses the processes",
                lambda v: True),
    **{k: ("names a print host, its device or its credentials; rigcad uploads nothing", _empty)
       for k in ("print_host", "printhost_apikey", "printhost_cafile", "printhost_port", "printhost_user",
                 "printhost_password", "octoprint_host", "octoprint_apikey", "octoprint_cafile", "serial_port")},
    **{k: ("a print host's setting; rigcad uploads nothing", lambda v: True)
       for k in ("host_type", "printhost_authorization_type", "serial_speed")},
    **{k: ("PrusaSlicer's own bookkeeping of its GUI presets, not the print", lambda v: True)
       for k in ("preset_name", "preset_names")},
}


def harmless(key: str, value: str) -> bool:
    """Whether a preset's value of a refused ``key`` may be left out quietly (see :data:`REFUSED`)."""
    test = REFUSED[key][1]
    return bool(test and test(value))


#: Physical ranges: key -> (low, high, unit, why). A per-extruder vector is checked element by
#: element; "nil" (inherit) and percentages of another setting are left to PrusaSlicer.
RANGES: dict[str, tuple[float, float, str, str]] = {
    **{k: (0.0, 500.0, "degC", "0 leaves the nozzle off; the hottest FFF hot ends (PEEK, PEI) reach 500 degC")
       for k in ("temperature", "first_layer_temperature")},
    **{k: (0.0, 200.0, "degC", "0 leaves the bed off; no FFF heated bed or chamber goes past 200 degC")
       for k in ("bed_temperature", "first_layer_bed_temperature")},
    "standby_temperature_delta": (-500.0, 500.0, "degC", "a change within the nozzle's whole range"),
    **{k: (0.01, 2.0, "mm", "a layer at least 0.01 mm (below every FFF printer's finest, 0.025 mm in PrusaSlicer's "
                            "bundles; finer only multiplies layers) and at most 2 mm (above any nozzle's widest)")
       for k in ("layer_height", "first_layer_height")},
    **{k: (0.0, 2.0, "mm", "0 means automatic; at most 2 mm, above any nozzle's thickest layer")
       for k in ("min_layer_height", "max_layer_height")},
    "nozzle_diameter": (0.05, 5.0, "mm", "FFF nozzles range from 0.1 to about 2 mm"),
    "filament_diameter": (0.5, 5.0, "mm", "filament is 1.75, 2.85 or 3 mm"),
    "max_print_height": (1.0, 10000.0, "mm", "a printer's height, up to a 10 m large-format machine"),
    "fill_density": (0.0, 100.0, "%", "a share of the interior"),
    **{k: (0.0, 1000.0, "", "a count of shells or loops; 1000 is far past any part")
       for k in ("perimeters", "top_solid_layers", "bottom_solid_layers", "solid_layers", "skirts", "raft_layers")},
    **{k: (0.0, 2000.0, "mm/s", "no FFF printer moves faster than 2 m/s (PrusaSlicer's bundles: at most 333 mm/s)")
       for k in ("perimeter_speed", "small_perimeter_speed", "external_perimeter_speed", "infill_speed",
                 "solid_infill_speed", "top_solid_infill_speed", "support_material_speed",
                 "support_material_interface_speed", "bridge_speed", "gap_fill_speed", "ironing_speed",
                 "travel_speed", "travel_speed_z", "first_layer_speed", "first_layer_speed_over_raft",
                 "max_print_speed")},
}

#: Control characters but tab: never in a value (a raw line break would start a new setting; tabs
#: align comments in some vendors' G-code).
_CONTROL = re.compile(r"[\x00-\x08\x0a-\x1f\x7f]")
#: A temperature command with a literal value in custom G-code: M104/M109 nozzle, M140/M190 bed.
_TEMP_GCODE = re.compile(r"^\s*(M10[49]|M1[49]0)\b[^;\n]*?\b[SR](-?\d+(?:\.\d*)?)\b", re.M | re.I)
_GCODE_KEYS = ALLOWED["custom G-code (for the printer; never run here)"]


def why_refused(key: str) -> str:
    """One phrase saying why ``key`` is not handed to PrusaSlicer."""
    if key in REFUSED:
        return REFUSED[key][0]
    return "not a setting that shapes a print (rigcad passes only its allow-list, rigcad.fab.allowlist.ALLOWED)"


def value_problem(key: str, value: str) -> str | None:
    """What is wrong with ``value`` (PrusaSlicer's text form) for an allowed ``key``, or None."""
    if _CONTROL.search(value):
        return "holds a line break or another control character (a value is one line of text)"
    if key in RANGES:
        lo, hi, unit, why = RANGES[key]
        for item in value.split(","):
            item = item.strip()
            if not item or item == "nil" or (item.endswith("%") and key != "fill_density"):
                continue
            try:
                x = float(item.rstrip("%"))
            except ValueError:
                continue  # not a number: PrusaSlicer's own check names it
            if not lo <= x <= hi:
                return f"{item} {unit} is outside {lo:g}..{hi:g} {unit} ({why})".replace("  ", " ")
    if key in _GCODE_KEYS:
        text = value.replace("\\n", "\n")
        for m in _TEMP_GCODE.finditer(text):
            which = "temperature" if m.group(1).upper() in ("M104", "M109") else "bed_temperature"
            lo, hi, unit, why = RANGES[which]
            if not lo <= float(m.group(2)) <= hi:
                return f"{m.group(0).strip()!r} sets {m.group(2)} {unit}, outside {lo:g}..{hi:g} {unit} ({why})"
    return None


def check_override(key: str, value: str, where: str | None) -> None:
    """A printer file's ``slicer.overrides`` entry: refused unless allowed and in range."""
    if key in REFUSED:
        raise ProfileError(f"slicer.overrides.{key}: refused: {REFUSED[key][0]}; rigcad hands PrusaSlicer only the "
                           "settings that shape a print", where=where)
    problem = value_problem(key, value)
    if problem:
        raise ProfileError(f"slicer.overrides.{key}: {problem}", where=where)


def filter_preset(settings: dict[str, str], where) -> dict[str, str]:
    """A preset's settings (a vendor bundle's, flattened, or a user's .ini) with only the allowed
    keys: refused keys with a harmless value and unknown keys are left out; a refused key with
    any other value, or an allowed one out of range, raises a ProfileError at ``where(key)`` (its
    file:line). The value of a refused key is never shown: it may be a credential."""
    out: dict[str, str] = {}
    for key, value in settings.items():
        if key in ALLOWED_KEYS:
            problem = value_problem(key, value)
            if problem:
                raise ProfileError(f"PrusaSlicer setting {key}: {problem}", where=where(key))
            out[key] = value
        elif key in REFUSED and not harmless(key, value):
            raise ProfileError(f"PrusaSlicer setting {key} refused: {REFUSED[key][0]}; remove it from the file "
                               "(rigcad hands PrusaSlicer only the settings that shape a print)", where=where(key))
    return out


def check_config(settings: dict[str, str], what: str) -> None:
    """The configuration rigcad is about to hand PrusaSlicer, or read back from its outputs:
    every key allowed, every value one line and in range; a FabricationError otherwise (it
    would be a fault in rigcad, every source having been checked before)."""
    for key, value in settings.items():
        if key not in ALLOWED_KEYS:
            raise FabricationError(f"{what}: setting {key} is not handed to PrusaSlicer: {why_refused(key)}")
        problem = value_problem(key, value)
        if problem:
            raise FabricationError(f"{what}: setting {key} {problem}")
