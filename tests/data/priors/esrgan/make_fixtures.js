// Writes the fixtures of tests/priors/sr/esrgan_test.cpp with TensorFlow.js itself (pure
// JavaScript CPU backend), the runtime the @upscalerjs models are made for.
//
//   npm install --prefix /tmp/tfjs @tensorflow/tfjs@4.11.0
//   NODE_PATH=/tmp/tfjs/node_modules node tests/data/priors/esrgan/make_fixtures.js [npm dir]
//
// [npm dir] defaults to third_party/npm (where scripts/setup.sh installs the models).
//   tiny/model.json, tiny/group1-shard{1,2}of2.bin  a small layers model with every layer kind
//       the ESRGAN models use (even-sized "same" kernels too), weights split across two shards
//   tiny_input.npy, tiny_output.npy                 its input and TensorFlow.js output, NHWC
//   slim_x4_input.npy, slim_x4_output.npy           the same for esrgan-slim x4 (input in 0..255)
const fs = require('fs');
const path = require('path');
const tf = require('@tensorflow/tfjs');

const HERE = __dirname;
const NPM_DIR = process.argv[2] || path.join(HERE, '..', '..', '..', '..', 'third_party', 'npm');

// The custom layers of the @upscalerjs models, with the configs their model.json files carry.
class MultiplyBeta extends tf.layers.Layer {
  constructor(config) { super(config); this.beta = 0.2; }
  call(inputs) { return tf.mul(Array.isArray(inputs) ? inputs[0] : inputs, this.beta); }
  getConfig() { return {...super.getConfig(), beta: this.beta}; }
  static get className() { return 'MultiplyBeta'; }
}
class PixelShuffle2x extends tf.layers.Layer {
  constructor(config) { super(config); this.scale = 2; }
  computeOutputShape(shape) {
    return [shape[0], shape[1] && shape[1] * 2, shape[2] && shape[2] * 2, shape[3] / 4];
  }
  call(inputs) { return tf.depthToSpace(Array.isArray(inputs) ? inputs[0] : inputs, 2, 'NHWC'); }
  getConfig() { return {...super.getConfig(), scale: this.scale}; }
  static get className() { return 'PixelShuffle2x'; }
}
tf.serialization.registerClass(MultiplyBeta);
tf.serialization.registerClass(PixelShuffle2x);

// A deterministic pseudo-random sequence, so reruns write identical fixtures.
function sequence(count, seed, scale) {
  const values = new Float32Array(count);
  let state = seed;
  for (let i = 0; i < count; ++i) {
    state = (state * 1103515245 + 12345) % 2147483648;
    values[i] = (state / 2147483648) * scale;
  }
  return values;
}

function writeNpy(file, tensor) {
  const header = `{'descr': '<f4', 'fortran_order': False, 'shape': (${tensor.shape.join(', ')}), }`;
  const padded = header + ' '.repeat(63 - ((10 + header.length) % 64)) + '\n';
  const prefix = Buffer.concat([Buffer.from([0x93]), Buffer.from('NUMPY'), Buffer.from([1, 0]),
                                Buffer.from([padded.length & 255, padded.length >> 8])]);
  fs.writeFileSync(file, Buffer.concat([prefix, Buffer.from(padded, 'latin1'),
                                        Buffer.from(tensor.dataSync().buffer)]));
}

function tinyModel() {
  const input = tf.input({shape: [null, null, 3], name: 'LR'});
  const conv = (name, filters, kernel, padding, x) =>
      tf.layers.conv2d({name, filters, kernelSize: kernel, padding}).apply(x);
  const f1 = conv('F_1', 6, 3, 'same', input);
  const relu = tf.layers.activation({name: 'F_1_Relu', activation: 'relu'}).apply(f1);
  const squeeze = conv('LFF', 4, 1, 'valid', relu);
  const joined = tf.layers.concatenate({name: 'Concat', axis: 3}).apply([f1, squeeze]);
  const even = conv('Even', 6, 2, 'same', joined);
  const wide = conv('Wide', 6, [5, 4], 'same', even);
  const scaled = new MultiplyBeta({name: 'multiply_beta'}).apply(wide);
  const sum = tf.layers.add({name: 'Sum'}).apply([f1, scaled]);
  const up = tf.layers.upSampling2d({name: 'UPsample', size: [2, 2]}).apply(sum);
  const pre = conv('PreShuffle', 12, 3, 'same', up);
  const output = new PixelShuffle2x({name: 'pixel_shuffle'}).apply(pre);
  const model = tf.model({inputs: input, outputs: output, name: 'tiny'});
  for (const [i, weight] of model.weights.entries()) {
    const values = sequence(weight.shape.reduce((a, b) => a * b, 1), 17 + i, 1);
    weight.write(tf.tensor(values, weight.shape).sub(0.5));
  }
  return model;
}

async function saveSplit(model, folder) {
  fs.mkdirSync(folder, {recursive: true});
  await model.save(tf.io.withSaveHandler(async (artifacts) => {
    const data = Buffer.from(artifacts.weightData);
    const cut = 1234;  // a shard boundary inside a weight, as the converter's 4 MB shards allow
    const paths = ['group1-shard1of2.bin', 'group1-shard2of2.bin'];
    fs.writeFileSync(path.join(folder, paths[0]), data.subarray(0, cut));
    fs.writeFileSync(path.join(folder, paths[1]), data.subarray(cut));
    const json = {format: 'layers-model', generatedBy: 'TensorFlow.js tfjs-layers v4.11.0',
                  convertedBy: null, modelTopology: artifacts.modelTopology,
                  weightsManifest: [{paths, weights: artifacts.weightSpecs}]};
    fs.writeFileSync(path.join(folder, 'model.json'), JSON.stringify(json));
    return {modelArtifactsInfo: {dateSaved: new Date(), modelTopologyType: 'JSON'}};
  }));
}

async function loadFolder(folder) {
  const json = JSON.parse(fs.readFileSync(path.join(folder, 'model.json')));
  const group = json.weightsManifest[0];
  const data = Buffer.concat(group.paths.map((p) => fs.readFileSync(path.join(folder, p))));
  return tf.loadLayersModel(tf.io.fromMemory({
    modelTopology: json.modelTopology, weightSpecs: group.weights,
    weightData: data.buffer.slice(data.byteOffset, data.byteOffset + data.length)}));
}

async function writeReference(model, name, shape, scale) {
  const input = tf.tensor(sequence(shape.reduce((a, b) => a * b, 1), 7, scale), shape);
  writeNpy(path.join(HERE, `${name}_input.npy`), input);
  writeNpy(path.join(HERE, `${name}_output.npy`), model.predict(input));
}

async function main() {
  const tinyFolder = path.join(HERE, 'tiny');
  await saveSplit(tinyModel(), tinyFolder);
  await writeReference(await loadFolder(tinyFolder), 'tiny', [1, 5, 7, 3], 1);
  const slim = path.join(NPM_DIR, 'node_modules', '@upscalerjs', 'esrgan-slim', 'models', 'x4');
  await writeReference(await loadFolder(slim), 'slim_x4', [1, 9, 11, 3], 255);
}

main();
