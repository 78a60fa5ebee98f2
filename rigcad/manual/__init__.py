"""The rig for people: the assembly and calibration manual with its bill of materials
(``rigcad manual``) and the 3D view in the browser (``rigcad view``). Both take every part from
``rig.recipes`` and the purchased items from the profile and the printer."""
