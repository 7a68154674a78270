// Checks Kubernetes Job files offline, as `kubectl apply --validate=strict` would before
// anything reaches a cluster, plus what handlabel's sharding needs:
//  - the schema: kubernetes-models' validators, generated from the Kubernetes OpenAPI
//    schema of batch/v1 Job (Kubernetes 1.33: field types, required fields, enums);
//  - unknown fields (kubectl's strict field validation; the OpenAPI schema itself allows
//    them, kubeconform -strict forbids them): a field counts as known when the schema's
//    validator of its object reads it; map-valued fields (labels, resource requests)
//    have their keys read as well;
//  - the API server's Job rules that the schema cannot state: a Job's pods restart
//    Never or OnFailure, an Indexed Job sets completions, backoffLimitPerIndex needs
//    completionMode Indexed;
//  - handlabel's: the Job is Indexed (pod k labels shard k, from JOB_COMPLETION_INDEX),
//    its container sets HANDLABEL_SHARD_COUNT to spec.completions (Kubernetes does not
//    export the count) and runs `handlabel label --job ...`.
// With --self-test it also checks broken copies of every file (a wrong field type, a
// misspelt field, a missing required field, no completionMode, a shard count that is
// not completions) and fails unless each is rejected.
// Usage: node check-jobs.mjs [--self-test] FILE.yaml...
// Exit status: 0 passed, 1 failed, 2 bad usage.
import fs from 'node:fs';
import YAML from 'yaml';
import { Job } from 'kubernetes-models/batch/v1/Job';

// `value` copied with every object wrapped so that the keys the validator reads are
// recorded: `objects` gets one {path, value, read} per object.
function watched(value, path, objects) {
  if (value === null || typeof value !== 'object') return value;
  if (Array.isArray(value)) return value.map((v, i) => watched(v, `${path}/${i}`, objects));
  const read = new Set();
  objects.push({ path, value, read });
  const copy = {};
  for (const [key, v] of Object.entries(value)) copy[key] = watched(v, `${path}/${key}`, objects);
  return new Proxy(copy, {
    get(target, key, receiver) {
      if (typeof key === 'string') read.add(key);
      return Reflect.get(target, key, receiver);
    },
  });
}

// Schema problems and unknown fields of one Job.
function schemaProblems(doc) {
  const objects = [];
  const problems = [];
  try {
    // The model's validate() runs the generated validator on `this`; called on the
    // watched copy (constructing a Job would read every key itself).
    Job.prototype.validate.call(watched(doc, '', objects));
  } catch (e) {
    problems.push(...e.message.split(', ').map((m) => `schema: ${m}`));
  }
  for (const { path, value, read } of objects) {
    for (const key of Object.keys(value)) {
      if (!read.has(key)) problems.push(`unknown field ${path}/${key}`);
    }
  }
  return problems;
}

// The API server's Job rules and handlabel's sharding rules.
function jobRuleProblems(doc) {
  const problems = [];
  const spec = doc.spec || {};
  const pod = (spec.template && spec.template.spec) || {};
  if (!['Never', 'OnFailure'].includes(pod.restartPolicy)) {
    problems.push('spec.template.spec.restartPolicy: a Job needs Never or OnFailure');
  }
  if (spec.backoffLimitPerIndex !== undefined && spec.completionMode !== 'Indexed') {
    problems.push('spec.backoffLimitPerIndex: needs spec.completionMode: Indexed');
  }
  if (spec.completionMode !== 'Indexed') {
    problems.push('spec.completionMode: expected Indexed (pod k labels shard k from ' +
                  'JOB_COMPLETION_INDEX)');
  } else if (!Number.isInteger(spec.completions)) {
    problems.push('spec.completions: an Indexed Job needs the number of shards');
  }
  const labelers = (pod.containers || []).filter((c) => (c.command || [])[1] === 'label');
  if (labelers.length !== 1) {
    problems.push('spec.template.spec.containers: expected one running `handlabel label`');
    return problems;
  }
  const command = labelers[0].command;
  if (!/handlabel$/.test(command[0]) || !command.includes('--job')) {
    problems.push(`command: expected handlabel label --job JOB.yaml, got ${command.join(' ')}`);
  }
  const count = (labelers[0].env || []).find((e) => e.name === 'HANDLABEL_SHARD_COUNT');
  if (!count || count.value !== String(spec.completions)) {
    problems.push(`env HANDLABEL_SHARD_COUNT: expected "${spec.completions}" ` +
                  `(spec.completions), got ${count ? JSON.stringify(count.value) : 'none'}`);
  }
  return problems;
}

// Problems of every document of one YAML text (an empty list: it passed).
function fileProblems(text) {
  const problems = [];
  for (const document of YAML.parseAllDocuments(text)) {
    if (document.errors.length > 0) {
      problems.push(...document.errors.map((e) => `YAML: ${e.message}`));
      continue;
    }
    const doc = document.toJS();
    if (doc === null) continue;
    if (doc.apiVersion !== 'batch/v1' || doc.kind !== 'Job') {
      problems.push(`apiVersion/kind: expected batch/v1 Job, got ${doc.apiVersion} ${doc.kind}`);
      continue;
    }
    problems.push(...schemaProblems(doc), ...jobRuleProblems(doc));
  }
  return problems;
}

// Broken copies of a Job file's text: what breaks each, and the problem it must cause.
function brokenCopies(text) {
  const doc = YAML.parse(text);
  const copies = [];
  const edit = (what, expected, change) => {
    const copy = structuredClone(doc);
    change(copy.spec, copy.spec.template.spec.containers[0]);
    copies.push({ what, expected, text: YAML.stringify(copy) });
  };
  edit('completions as a string', /schema: data\/spec\/completions must be integer/,
       (s) => { s.completions = String(s.completions); });
  edit('misspelt parallelism', /unknown field \/spec\/paralelism/,
       (s) => { s.paralelism = s.parallelism; delete s.parallelism; });
  edit('misspelt container field', /unknown field \/spec\/template\/spec\/containers\/0\/imagePulPolicy/,
       (s, c) => { c.imagePulPolicy = 'Always'; });
  edit('container without a name', /containers\/0 must have required property name/,
       (s, c) => { delete c.name; });
  edit('completionMode misspelt', /completionMode must be equal to one of the allowed values/,
       (s) => { s.completionMode = 'indexed'; });
  edit('no completionMode', /spec.completionMode: expected Indexed/,
       (s) => { delete s.completionMode; });
  edit('restartPolicy Always', /restartPolicy: a Job needs Never or OnFailure/,
       (s) => { s.template.spec.restartPolicy = 'Always'; });
  edit('shard count other than completions', /env HANDLABEL_SHARD_COUNT: expected/,
       (s) => { s.completions += 1; });
  return copies;
}

const args = process.argv.slice(2);
const selfTest = args.includes('--self-test');
const files = args.filter((a) => a !== '--self-test');
if (files.length === 0) {
  console.error('usage: node check-jobs.mjs [--self-test] FILE.yaml...');
  process.exit(2);
}
let failed = false;
for (const file of files) {
  const text = fs.readFileSync(file, 'utf8');
  const problems = fileProblems(text);
  for (const p of problems) console.log(`${file}: ${p}`);
  console.log(`${file}: ${problems.length === 0 ? 'valid' : 'INVALID'}`);
  failed ||= problems.length > 0;
  if (!selfTest || problems.length > 0) continue;
  for (const { what, expected, text: broken } of brokenCopies(text)) {
    const found = fileProblems(broken);
    const hit = found.find((p) => expected.test(p));
    console.log(`${file} with ${what}: ` +
                (hit ? `rejected (${hit})` : `NOT REJECTED as expected (${expected}): ` +
                                             `${found.join('; ') || 'no problem found'}`));
    failed ||= !hit;
  }
}
process.exit(failed ? 1 : 0);
