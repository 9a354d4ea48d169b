// The 11-tap SSIM window (loss_shared.h), unrolled by hand: no loop, no indexed local array (lavapipe
// spills those). TAP(k, w) adds w times the value at offset k along the pass's axis.
#define SSIM_WINDOW(TAP)                                                               \
  TAP(-5, SSIM_W5) TAP(-4, SSIM_W4) TAP(-3, SSIM_W3) TAP(-2, SSIM_W2) TAP(-1, SSIM_W1) \
  TAP(0, SSIM_W0) TAP(1, SSIM_W1) TAP(2, SSIM_W2) TAP(3, SSIM_W3) TAP(4, SSIM_W4) TAP(5, SSIM_W5)

// Zero padding without branches: the tap at coordinate c + k (of n) reads the clamped (in-bounds) element
// and weighs it 0 when c + k is outside, so every lane loads and none diverges.
#define SSIM_TAP_WEIGHT(c, k, n, wk) ((c) + (k) >= 0 && (c) + (k) < (n) ? float(wk) : 0.0)
#define SSIM_TAP_OFFSET(c, k, n) (clamp((c) + (k), 0, (n)-1) - (c))
