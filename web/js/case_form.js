// The case editor: a case object (cantilever and sample inline, as the module's CaseRequest
// reads it) shown as form fields, and read back with every number checked to be a number
// (ranges are the module's to check, with the command line's messages).

/** Default parameters of each contact law when first chosen (MODEL.md section 9's examples). */
const LAW_DEFAULTS = {
  hertz: { tip_shape: "sphere" },
  dmt: { hamaker_constant_j: 5e-22, intermolecular_distance_nm: 0.165 },
  "kelvin-voigt": { viscosity_pa_s: 10, clip: true },
  film: { thickness_nm: 6, correction: "garcia-2018" },
};
const DOUBLE_LAYER_DEFAULT = {
  debye_length_nm: 1,
  tip_charge_c_per_m2: -0.02,
  sample_charge_c_per_m2: -0.02,
  relative_permittivity: 80,
};

const CANTILEVER_FIELDS = [
  ["tip_radius_nm", "tip radius R (nm)"],
  ["tip_mass_ratio", "tip mass / beam mass"],
  ["tip_youngs_modulus_gpa", "tip Young's modulus (GPa)"],
  ["tip_poisson_ratio", "tip Poisson ratio"],
];
const MODE_FIELDS = ["stiffness_n_per_m", "frequency_khz", "quality_factor", "optical_sensitivity", "force_ratio"];
const SAMPLE_FIELDS = [
  ["youngs_modulus_gpa", "sample Young's modulus (GPa)"],
  ["poisson_ratio", "sample Poisson ratio"],
];
const LAW_FIELDS = {
  hertz: {
    sphere: [],
    cone: [["cone_half_angle_deg", "cone half-angle (deg)", 20]],
    "flat-punch": [["punch_radius_nm", "punch radius (nm)", 10]],
  },
  dmt: [["hamaker_constant_j", "Hamaker constant H (J)"], ["intermolecular_distance_nm", "intermolecular distance a0 (nm)"]],
  "kelvin-voigt": [["viscosity_pa_s", "viscosity (Pa s)"]],
  film: [["thickness_nm", "film thickness h (nm)"]],
};
const DOUBLE_LAYER_FIELDS = [
  ["debye_length_nm", "Debye length (nm)"],
  ["tip_charge_c_per_m2", "tip charge (C/m\u00b2)"],
  ["sample_charge_c_per_m2", "sample charge (C/m\u00b2)"],
  ["relative_permittivity", "relative permittivity"],
];

function numberInput(id, label, value) {
  const wrapper = document.createElement("label");
  wrapper.textContent = label + " ";
  const input = document.createElement("input");
  input.type = "number";
  input.step = "any";
  input.id = id;
  input.dataset.label = label;
  input.value = value ?? "";
  wrapper.appendChild(input);
  return wrapper;
}

function selectInput(id, label, options, value) {
  const wrapper = document.createElement("label");
  wrapper.textContent = label + " ";
  const select = document.createElement("select");
  select.id = id;
  for (const option of options) select.add(new Option(option, option));
  select.value = value;
  wrapper.appendChild(select);
  return wrapper;
}

/** A number read from the input `input`; an error naming its label when it is not one. */
export function readNumber(input, { optional = false } = {}) {
  const text = input.value.trim();
  if (text === "" && optional) {
    input.classList.remove("invalid");
    return null;
  }
  const value = Number(text);
  if (text === "" || !Number.isFinite(value)) {
    input.classList.add("invalid");
    throw new Error(`${input.dataset.label}: "${input.value}" is not a number`);
  }
  input.classList.remove("invalid");
  return value;
}

export class CaseForm {
  /** `onChange()` is called after every edit. */
  constructor(onChange) {
    this.onChange = onChange;
    this.base = null;
    for (const id of ["a0", "drive"]) document.getElementById(id).addEventListener("change", onChange);
    document.getElementById("add-mode").addEventListener("click", () => {
      const modes = this.readModes(false);
      const last = modes[modes.length - 1] ?? { stiffness_n_per_m: 1, frequency_khz: 10, quality_factor: 2, optical_sensitivity: 1, force_ratio: 1 };
      modes.push({ ...last, frequency_khz: last.frequency_khz * 6.27, stiffness_n_per_m: last.stiffness_n_per_m * 39.3 });
      this.renderModes(modes);
      onChange();
    });
    document.getElementById("contact-law").addEventListener("change", (event) => {
      this.renderContact({ law: event.target.value, ...LAW_DEFAULTS[event.target.value] });
      onChange();
    });
    document.getElementById("double-layer").addEventListener("change", (event) => {
      this.renderDoubleLayer(event.target.checked ? DOUBLE_LAYER_DEFAULT : null);
      onChange();
    });
    for (const id of ["cantilever-fields", "sample-fields", "contact-fields", "double-layer-fields", "modes"]) {
      document.getElementById(id).addEventListener("change", (event) => {
        if (event.target.id === "tip-shape") {
          this.renderContact({ law: "hertz", tip_shape: event.target.value });
        }
        onChange();
      });
    }
  }

  /** Show `caseObject` (the catalogue's form: cantilever and sample objects inline). */
  show(caseObject) {
    this.base = structuredClone(caseObject);
    document.getElementById("a0").value = caseObject.free_amplitude_nm;
    document.getElementById("drive").value = caseObject.drive_frequency_khz ?? "";
    const cantilever = document.getElementById("cantilever-fields");
    cantilever.replaceChildren(...CANTILEVER_FIELDS.map(([key, label]) => numberInput(`cantilever-${key}`, label, caseObject.cantilever[key])));
    this.renderModes(caseObject.cantilever.modes);
    const sample = document.getElementById("sample-fields");
    sample.replaceChildren(...SAMPLE_FIELDS.map(([key, label]) => numberInput(`sample-${key}`, label, caseObject.sample[key])));
    this.renderContact(caseObject.sample.contact ?? { law: "hertz", tip_shape: "sphere" });
    this.renderDoubleLayer(caseObject.sample.electrostatic ?? null);
  }

  renderModes(modes) {
    const body = document.querySelector("#modes tbody");
    body.replaceChildren();
    modes.forEach((mode, i) => {
      const row = body.insertRow();
      row.insertCell().textContent = String(i + 1);
      for (const key of MODE_FIELDS) {
        const input = document.createElement("input");
        input.type = "number";
        input.step = "any";
        input.value = mode[key];
        input.dataset.key = key;
        input.dataset.label = `mode ${i + 1} ${key}`;
        row.insertCell().appendChild(input);
      }
      const remove = document.createElement("button");
      remove.type = "button";
      remove.textContent = "\u00d7";
      remove.title = `remove mode ${i + 1}`;
      remove.disabled = modes.length === 1;
      remove.addEventListener("click", () => {
        const current = this.readModes(false);
        current.splice(i, 1);
        this.renderModes(current);
        this.onChange();
      });
      row.insertCell().appendChild(remove);
    });
  }

  /** The modes in the table; `strict`: every entry must be a number. */
  readModes(strict = true) {
    return [...document.querySelectorAll("#modes tbody tr")].map((row) => {
      const mode = {};
      for (const input of row.querySelectorAll("input")) {
        mode[input.dataset.key] = strict ? readNumber(input) : Number(input.value);
      }
      return mode;
    });
  }

  renderContact(contact) {
    document.getElementById("contact-law").value = contact.law;
    const fields = document.getElementById("contact-fields");
    fields.replaceChildren();
    if (contact.law === "hertz") {
      const shape = contact.tip_shape ?? "sphere";
      fields.appendChild(selectInput("tip-shape", "tip shape", ["sphere", "cone", "flat-punch"], shape));
      for (const [key, label, fallback] of LAW_FIELDS.hertz[shape]) {
        fields.appendChild(numberInput(`contact-${key}`, label, contact[key] ?? fallback));
      }
    } else {
      for (const [key, label] of LAW_FIELDS[contact.law]) {
        fields.appendChild(numberInput(`contact-${key}`, label, contact[key]));
      }
      if (contact.law === "kelvin-voigt") {
        const wrapper = document.createElement("label");
        wrapper.className = "check";
        const box = document.createElement("input");
        box.type = "checkbox";
        box.id = "contact-clip";
        box.checked = contact.clip ?? true;
        wrapper.append(box, " force clipped at zero (no pull-off)");
        fields.appendChild(wrapper);
      }
      if (contact.law === "film") {
        fields.appendChild(selectInput("contact-correction", "bottom-effect correction",
          ["garcia-2018", "dimitriadis-2002-bonded", "dimitriadis-2002-non-bonded"], contact.correction ?? "garcia-2018"));
      }
    }
  }

  renderDoubleLayer(layer) {
    document.getElementById("double-layer").checked = layer !== null;
    const fields = document.getElementById("double-layer-fields");
    fields.replaceChildren(...(layer === null ? [] : DOUBLE_LAYER_FIELDS.map(([key, label]) => numberInput(`layer-${key}`, label, layer[key]))));
  }

  readContact() {
    const law = document.getElementById("contact-law").value;
    if (law === "hertz") {
      const shape = document.getElementById("tip-shape").value;
      if (shape === "sphere") return undefined; // the files' default: Hertz with a sphere
      const contact = { law, tip_shape: shape };
      for (const [key] of LAW_FIELDS.hertz[shape]) contact[key] = readNumber(document.getElementById(`contact-${key}`));
      return contact;
    }
    const contact = { law };
    for (const [key] of LAW_FIELDS[law]) contact[key] = readNumber(document.getElementById(`contact-${key}`));
    if (law === "kelvin-voigt") contact.clip = document.getElementById("contact-clip").checked;
    if (law === "film") contact.correction = document.getElementById("contact-correction").value;
    return contact;
  }

  /** The edited case (a CaseRequest); throws an Error naming the field that is not a number. */
  read() {
    const base = structuredClone(this.base);
    const cantilever = base.cantilever;
    for (const [key] of CANTILEVER_FIELDS) cantilever[key] = readNumber(document.getElementById(`cantilever-${key}`));
    cantilever.modes = this.readModes();
    const sample = base.sample;
    for (const [key] of SAMPLE_FIELDS) sample[key] = readNumber(document.getElementById(`sample-${key}`));
    const contact = this.readContact();
    if (contact === undefined) delete sample.contact;
    else sample.contact = contact;
    if (document.getElementById("double-layer").checked) {
      sample.electrostatic = {};
      for (const [key] of DOUBLE_LAYER_FIELDS) sample.electrostatic[key] = readNumber(document.getElementById(`layer-${key}`));
    } else {
      delete sample.electrostatic;
    }
    return {
      name: base.name,
      description: base.description,
      cantilever,
      sample,
      free_amplitude_nm: readNumber(document.getElementById("a0")),
      drive_frequency_khz: readNumber(document.getElementById("drive"), { optional: true }),
      // The excitation (direct, acoustic or bimodal) is not edited here: kept from the case.
      drive: base.drive,
    };
  }
}
