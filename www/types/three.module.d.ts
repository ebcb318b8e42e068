// Types of www/vendor/three.module.js (three.js, copied there from npm by `make pkg`): those of
// the npm package (@types/three, the same version). `make pkg` copies this file beside it.
export * from 'three';
