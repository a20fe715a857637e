/* Configuration, prior and argument checks; status names; layout functions. */
#include "test_common.h"

#include "icoac_internal.h"

#define NAN_R ((icoac_real_t)NAN)
#define INF_R ((icoac_real_t)INFINITY)

static void test_defaults_match_spec(void **unused)
{
    icoac_config_t cfg = test_default_config();
    const double tol = 4.0 * REAL_EPS;
    (void)unused;
    assert_int_equal(cfg.mode, ICOAC_MODE_ICO);
    assert_int_equal(cfg.reflex_mode, ICOAC_REFLEX_UNIT);
    assert_int_equal(cfg.ico_timing, ICOAC_ICO_TIMING_CODE);
    assert_int_equal(cfg.clip_inputs, 1);
    assert_close(cfg.input_range[0], 2.4, tol * 2.4);
    assert_close(cfg.input_range[1], 3.5, tol * 3.5);
    assert_close(cfg.input_range[2], 0.2094384, tol);
    assert_close(cfg.input_range[3], 2.0, 0.0);
    assert_close(cfg.gain, 10.0, 0.0);
    assert_close(cfg.reflex_force, 1.0, 0.0);
    assert_close(cfg.zone_theta, DEG(11.5), tol);
    assert_close(cfg.zone_x, 2.35, tol * 2.35);
    assert_close(cfg.ico_rate, 1e-4, tol * 1e-4);
    assert_close(cfg.critic_rate, 0.6, tol);
    assert_close(cfg.discount, 0.95, tol);
    assert_close(cfg.td_clip, 1.0, 0.0);
    assert_close(cfg.critic_range[0], 2.4, tol * 2.4);
    assert_close(cfg.critic_range[1], 3.5, tol * 3.5);
    assert_close(cfg.critic_range[2], 0.2094384, tol);
    assert_close(cfg.critic_range[3], 2.0, 0.0);
    assert_close(cfg.noise_std, 1.0, 0.0);
    assert_close(cfg.actor_scale, 0.5, 0.0);
    assert_close(cfg.forgetting, 1.0, 0.0);
    assert_int_equal(cfg.rl_reflex, 1);
    assert_int_equal(cfg.act_with_sample, 0);
    icoac_config_default(NULL); /* must not crash */
}

/* One mutation of the default configuration and the status it must produce. */
typedef void (*mutate_fn)(icoac_config_t *cfg);
typedef struct {
    const char *name;
    mutate_fn mutate;
    icoac_status_t expected;
} config_case_t;

#define MUT(fname, body) \
    static void fname(icoac_config_t *c) { body; }

MUT(m_mode_2, c->mode = 2)
MUT(m_mode_neg, c->mode = -1)
MUT(m_reflex_mode_2, c->reflex_mode = 2)
MUT(m_reflex_mode_neg, c->reflex_mode = -1)
MUT(m_timing_2, c->ico_timing = 2)
MUT(m_clip_2, c->clip_inputs = 2)
MUT(m_clip_neg, c->clip_inputs = -1)
MUT(m_rl_reflex_2, c->rl_reflex = 2)
MUT(m_sample_2, c->act_with_sample = 2)
MUT(m_range0_zero, c->input_range[0] = 0)
MUT(m_range1_neg, c->input_range[1] = -3.5f)
MUT(m_range2_nan, c->input_range[2] = NAN_R)
MUT(m_range3_inf, c->input_range[3] = INF_R)
MUT(m_gain_neg, c->gain = -1.0f)
MUT(m_gain_nan, c->gain = NAN_R)
MUT(m_gain_inf, c->gain = INF_R)
MUT(m_reflex_force_neg, c->reflex_force = -0.1f)
MUT(m_reflex_force_nan, c->reflex_force = NAN_R)
MUT(m_zone_theta_zero, c->zone_theta = 0)
MUT(m_zone_theta_nan, c->zone_theta = NAN_R)
MUT(m_zone_x_neg, c->zone_x = -2.35f)
MUT(m_zone_x_inf, c->zone_x = INF_R)
MUT(m_ico_rate_neg, c->ico_rate = -1e-9f)
MUT(m_ico_rate_nan, c->ico_rate = NAN_R)
MUT(m_ico_rate_inf, c->ico_rate = INF_R)
MUT(m_critic_rate_neg, c->critic_rate = -0.1f)
MUT(m_critic_rate_big, c->critic_rate = 10.5f)
MUT(m_critic_rate_nan, c->critic_rate = NAN_R)
MUT(m_discount_neg, c->discount = -0.01f)
MUT(m_discount_big, c->discount = 1.01f)
MUT(m_discount_nan, c->discount = NAN_R)
MUT(m_td_clip_zero, c->td_clip = 0)
MUT(m_td_clip_nan, c->td_clip = NAN_R)
MUT(m_critic_range0_zero, c->critic_range[0] = 0)
MUT(m_critic_range2_nan, c->critic_range[2] = NAN_R)
MUT(m_critic_range3_neg, c->critic_range[3] = -2.0f)
MUT(m_threshold_neg, c->critic_threshold = -0.001f)
MUT(m_threshold_one, c->critic_threshold = 1.0f)
MUT(m_threshold_nan, c->critic_threshold = NAN_R)
MUT(m_noise_zero, c->noise_std = 0)
MUT(m_noise_nan, c->noise_std = NAN_R)
MUT(m_noise_inf, c->noise_std = INF_R)
MUT(m_scale_neg, c->actor_scale = -0.5f)
MUT(m_scale_nan, c->actor_scale = NAN_R)
MUT(m_forget_zero, c->forgetting = 0)
MUT(m_forget_big, c->forgetting = 1.001f)
MUT(m_forget_nan, c->forgetting = NAN_R)
/* Issue 8: accepted before, then NaN/Inf (or a critic overrun) in the tick. Both ends bounded. */
MUT(m_range0_subnormal, c->input_range[0] = (icoac_real_t)1e-39)
MUT(m_range1_tiny, c->input_range[1] = (icoac_real_t)9e-7)
MUT(m_range2_huge, c->input_range[2] = (icoac_real_t)1.1e6)
MUT(m_gain_huge, c->gain = (icoac_real_t)1e30)
MUT(m_reflex_force_huge, c->reflex_force = (icoac_real_t)1e38)
MUT(m_zone_theta_big, c->zone_theta = (icoac_real_t)3.2)
MUT(m_zone_x_huge, c->zone_x = (icoac_real_t)1e30)
MUT(m_ico_rate_huge, c->ico_rate = (icoac_real_t)1e30)
MUT(m_td_clip_subnormal, c->td_clip = (icoac_real_t)1e-39)
MUT(m_td_clip_huge, c->td_clip = (icoac_real_t)1e30)
MUT(m_critic_range0_subnormal, { c->mode = ICOAC_MODE_RL; c->critic_range[0] = (icoac_real_t)1e-39; })
MUT(m_critic_range1_huge, c->critic_range[1] = (icoac_real_t)1e30)
MUT(m_noise_tiny, { c->mode = ICOAC_MODE_RL; c->noise_std = (icoac_real_t)1e-20; })
MUT(m_noise_huge, c->noise_std = (icoac_real_t)1e30)
MUT(m_scale_huge, c->actor_scale = (icoac_real_t)1e30)
MUT(m_forget_tiny, c->forgetting = (icoac_real_t)1e-30)
MUT(m_forget_below_half, c->forgetting = (icoac_real_t)0.49)
MUT(m_zone_theta_subnormal, c->zone_theta = (icoac_real_t)(REAL_IS_FLOAT ? 1e-39 : 1e-310))
MUT(m_zone_x_tiny, c->zone_x = (icoac_real_t)9e-7)
MUT(m_gain_subnormal, c->gain = (icoac_real_t)(REAL_IS_FLOAT ? 1e-39 : 1e-310))
MUT(m_threshold_subnormal, c->critic_threshold = (icoac_real_t)(REAL_IS_FLOAT ? 1e-39 : 1e-310))
/* Boundary values that are valid. */
MUT(ok_range_bounds, { c->input_range[0] = (icoac_real_t)1e-6; c->input_range[1] = (icoac_real_t)1e6;
                       c->critic_range[2] = (icoac_real_t)1e-6; c->critic_range[3] = (icoac_real_t)1e6; })
MUT(ok_upper_bounds, { c->gain = (icoac_real_t)1e4; c->reflex_force = (icoac_real_t)1e4;
                       c->ico_rate = 1; c->td_clip = (icoac_real_t)1e3; c->noise_std = (icoac_real_t)1e3;
                       c->actor_scale = (icoac_real_t)1e3; })
MUT(ok_lower_bounds, { c->td_clip = (icoac_real_t)1e-6; c->noise_std = (icoac_real_t)1e-3; })
MUT(ok_gain_zero, c->gain = 0)
MUT(ok_reflex_force_zero, c->reflex_force = 0)
MUT(ok_ico_rate_zero, c->ico_rate = 0)
MUT(ok_discount_zero, c->discount = 0)
MUT(ok_discount_one, c->discount = 1)
MUT(ok_critic_rate_ten, c->critic_rate = 10)
MUT(ok_threshold, c->critic_threshold = 0.999f)
MUT(ok_forget, c->forgetting = 0.5f)
MUT(ok_scale_zero, c->actor_scale = 0)
MUT(ok_rl_gain_literal, { c->mode = ICOAC_MODE_RL; c->reflex_mode = ICOAC_REFLEX_GAIN;
                          c->ico_timing = ICOAC_ICO_TIMING_LITERAL; c->clip_inputs = 0;
                          c->rl_reflex = 0; c->act_with_sample = 1; })

static const config_case_t config_cases[] = {
    {"mode=2", m_mode_2, ICOAC_ERR_BAD_MODE},
    {"mode=-1", m_mode_neg, ICOAC_ERR_BAD_MODE},
    {"reflex_mode=2", m_reflex_mode_2, ICOAC_ERR_BAD_MODE},
    {"reflex_mode=-1", m_reflex_mode_neg, ICOAC_ERR_BAD_MODE},
    {"ico_timing=2", m_timing_2, ICOAC_ERR_BAD_MODE},
    {"clip_inputs=2", m_clip_2, ICOAC_ERR_BAD_MODE},
    {"clip_inputs=-1", m_clip_neg, ICOAC_ERR_BAD_MODE},
    {"rl_reflex=2", m_rl_reflex_2, ICOAC_ERR_BAD_MODE},
    {"act_with_sample=2", m_sample_2, ICOAC_ERR_BAD_MODE},
    {"input_range[0]=0", m_range0_zero, ICOAC_ERR_BAD_SCALE},
    {"input_range[1]<0", m_range1_neg, ICOAC_ERR_BAD_SCALE},
    {"input_range[2]=NaN", m_range2_nan, ICOAC_ERR_BAD_SCALE},
    {"input_range[3]=Inf", m_range3_inf, ICOAC_ERR_BAD_SCALE},
    {"gain<0", m_gain_neg, ICOAC_ERR_BAD_GAIN},
    {"gain=NaN", m_gain_nan, ICOAC_ERR_BAD_GAIN},
    {"gain=Inf", m_gain_inf, ICOAC_ERR_BAD_GAIN},
    {"reflex_force<0", m_reflex_force_neg, ICOAC_ERR_BAD_GAIN},
    {"reflex_force=NaN", m_reflex_force_nan, ICOAC_ERR_BAD_GAIN},
    {"zone_theta=0", m_zone_theta_zero, ICOAC_ERR_BAD_ZONE},
    {"zone_theta=NaN", m_zone_theta_nan, ICOAC_ERR_BAD_ZONE},
    {"zone_x<0", m_zone_x_neg, ICOAC_ERR_BAD_ZONE},
    {"zone_x=Inf", m_zone_x_inf, ICOAC_ERR_BAD_ZONE},
    {"ico_rate<0", m_ico_rate_neg, ICOAC_ERR_BAD_ICO_RATE},
    {"ico_rate=NaN", m_ico_rate_nan, ICOAC_ERR_BAD_ICO_RATE},
    {"ico_rate=Inf", m_ico_rate_inf, ICOAC_ERR_BAD_ICO_RATE},
    {"critic_rate<0", m_critic_rate_neg, ICOAC_ERR_BAD_CRITIC},
    {"critic_rate>10", m_critic_rate_big, ICOAC_ERR_BAD_CRITIC},
    {"critic_rate=NaN", m_critic_rate_nan, ICOAC_ERR_BAD_CRITIC},
    {"discount<0", m_discount_neg, ICOAC_ERR_BAD_CRITIC},
    {"discount>1", m_discount_big, ICOAC_ERR_BAD_CRITIC},
    {"discount=NaN", m_discount_nan, ICOAC_ERR_BAD_CRITIC},
    {"td_clip=0", m_td_clip_zero, ICOAC_ERR_BAD_CRITIC},
    {"td_clip=NaN", m_td_clip_nan, ICOAC_ERR_BAD_CRITIC},
    {"critic_range[0]=0", m_critic_range0_zero, ICOAC_ERR_BAD_CRITIC},
    {"critic_range[2]=NaN", m_critic_range2_nan, ICOAC_ERR_BAD_CRITIC},
    {"critic_range[3]<0", m_critic_range3_neg, ICOAC_ERR_BAD_CRITIC},
    {"critic_threshold<0", m_threshold_neg, ICOAC_ERR_BAD_CRITIC},
    {"critic_threshold=1", m_threshold_one, ICOAC_ERR_BAD_CRITIC},
    {"critic_threshold=NaN", m_threshold_nan, ICOAC_ERR_BAD_CRITIC},
    {"noise_std=0", m_noise_zero, ICOAC_ERR_BAD_ACTOR},
    {"noise_std=NaN", m_noise_nan, ICOAC_ERR_BAD_ACTOR},
    {"noise_std=Inf", m_noise_inf, ICOAC_ERR_BAD_ACTOR},
    {"actor_scale<0", m_scale_neg, ICOAC_ERR_BAD_ACTOR},
    {"actor_scale=NaN", m_scale_nan, ICOAC_ERR_BAD_ACTOR},
    {"forgetting=0", m_forget_zero, ICOAC_ERR_BAD_ACTOR},
    {"forgetting>1", m_forget_big, ICOAC_ERR_BAD_ACTOR},
    {"forgetting=NaN", m_forget_nan, ICOAC_ERR_BAD_ACTOR},
    {"input_range[0]=1e-39", m_range0_subnormal, ICOAC_ERR_BAD_SCALE},
    {"input_range[1]=9e-7", m_range1_tiny, ICOAC_ERR_BAD_SCALE},
    {"input_range[2]=1.1e6", m_range2_huge, ICOAC_ERR_BAD_SCALE},
    {"gain=1e30", m_gain_huge, ICOAC_ERR_BAD_GAIN},
    {"reflex_force=1e38", m_reflex_force_huge, ICOAC_ERR_BAD_GAIN},
    {"zone_theta=3.2", m_zone_theta_big, ICOAC_ERR_BAD_ZONE},
    {"zone_x=1e30", m_zone_x_huge, ICOAC_ERR_BAD_ZONE},
    {"ico_rate=1e30", m_ico_rate_huge, ICOAC_ERR_BAD_ICO_RATE},
    {"td_clip=1e-39", m_td_clip_subnormal, ICOAC_ERR_BAD_CRITIC},
    {"td_clip=1e30", m_td_clip_huge, ICOAC_ERR_BAD_CRITIC},
    {"RL, critic_range[0]=1e-39", m_critic_range0_subnormal, ICOAC_ERR_BAD_CRITIC},
    {"critic_range[1]=1e30", m_critic_range1_huge, ICOAC_ERR_BAD_CRITIC},
    {"RL, noise_std=1e-20", m_noise_tiny, ICOAC_ERR_BAD_ACTOR},
    {"noise_std=1e30", m_noise_huge, ICOAC_ERR_BAD_ACTOR},
    {"actor_scale=1e30", m_scale_huge, ICOAC_ERR_BAD_ACTOR},
    {"forgetting=1e-30", m_forget_tiny, ICOAC_ERR_BAD_ACTOR},
    {"forgetting=0.49", m_forget_below_half, ICOAC_ERR_BAD_ACTOR},
    {"zone_theta subnormal", m_zone_theta_subnormal, ICOAC_ERR_BAD_ZONE},
    {"zone_x=9e-7", m_zone_x_tiny, ICOAC_ERR_BAD_ZONE},
    {"gain subnormal", m_gain_subnormal, ICOAC_ERR_BAD_GAIN},
    {"critic_threshold subnormal", m_threshold_subnormal, ICOAC_ERR_BAD_CRITIC},
    {"ranges at their bounds", ok_range_bounds, ICOAC_OK},
    {"upper bounds", ok_upper_bounds, ICOAC_OK},
    {"lower bounds", ok_lower_bounds, ICOAC_OK},
    {"gain=0", ok_gain_zero, ICOAC_OK},
    {"reflex_force=0", ok_reflex_force_zero, ICOAC_OK},
    {"ico_rate=0", ok_ico_rate_zero, ICOAC_OK},
    {"discount=0", ok_discount_zero, ICOAC_OK},
    {"discount=1", ok_discount_one, ICOAC_OK},
    {"critic_rate=10", ok_critic_rate_ten, ICOAC_OK},
    {"critic_threshold=0.999", ok_threshold, ICOAC_OK},
    {"forgetting=0.5", ok_forget, ICOAC_OK},
    {"actor_scale=0", ok_scale_zero, ICOAC_OK},
    {"all switches at their alternative", ok_rl_gain_literal, ICOAC_OK},
};

static void test_bad_configs_rejected_state_untouched(void **unused)
{
    size_t n;
    int seen[ICOAC_ERR_BAD_PRIOR + 1] = {0};
    int s;
    (void)unused;
    for (n = 0; n < sizeof config_cases / sizeof config_cases[0]; ++n) {
        const config_case_t *c = &config_cases[n];
        icoac_config_t cfg = test_default_config();
        icoac_state_t state;
        icoac_state_t sentinel;
        icoac_status_t got;
        c->mutate(&cfg);
        got = icoac_config_check(&cfg);
        if (got != c->expected) {
            print_error("case %s: icoac_config_check -> %d, expected %d\n", c->name, (int)got,
                        (int)c->expected);
        }
        assert_int_equal(got, c->expected);
        memset(&state, 0xA5, sizeof state);
        memset(&sentinel, 0xA5, sizeof sentinel);
        got = icoac_init(&cfg, &state, NULL, 7u);
        if (got != c->expected) {
            print_error("case %s: icoac_init -> %d, expected %d\n", c->name, (int)got, (int)c->expected);
        }
        assert_int_equal(got, c->expected);
        if (c->expected != ICOAC_OK) {
            if (memcmp(&state, &sentinel, sizeof state) != 0) {
                print_error("case %s: icoac_init touched the state\n", c->name);
                fail();
            }
        } else {
            assert_int_equal(state.magic, ICOAC_STATE_MAGIC);
        }
        seen[c->expected] = 1;
    }
    /* Every named configuration status is exercised. */
    for (s = ICOAC_ERR_BAD_MODE; s <= ICOAC_ERR_BAD_ACTOR; ++s) {
        assert_true(seen[s]);
    }
}

static void expect_bad_prior(const icoac_prior_t *prior, const char *name)
{
    icoac_config_t cfg = test_default_config();
    icoac_state_t state;
    icoac_state_t sentinel;
    icoac_status_t got;
    int mode;
    assert_int_equal(icoac_prior_check(prior), ICOAC_ERR_BAD_PRIOR);
    for (mode = ICOAC_MODE_ICO; mode <= ICOAC_MODE_RL; ++mode) {
        cfg.mode = mode;
        memset(&state, 0x5A, sizeof state);
        memset(&sentinel, 0x5A, sizeof sentinel);
        got = icoac_init(&cfg, &state, prior, 1u);
        if (got != ICOAC_ERR_BAD_PRIOR) {
            print_error("prior %s: icoac_init -> %d\n", name, (int)got);
        }
        assert_int_equal(got, ICOAC_ERR_BAD_PRIOR);
        assert_memory_equal(&state, &sentinel, sizeof state);
    }
}

static void test_bad_priors(void **unused)
{
    icoac_prior_t p;
    (void)unused;
    /* Non-symmetric (but with a PD symmetric part). */
    p = test_prior(0, 0, 0, 0, 1.0);
    p.cov[0][1] = (icoac_real_t)0.1;
    expect_bad_prior(&p, "non-symmetric");
    /* Symmetric, indefinite: eigenvalues of [[1,2],[2,1]] are 3 and -1. */
    p = test_prior(0, 0, 0, 0, 1.0);
    p.cov[1][2] = p.cov[2][1] = (icoac_real_t)2.0;
    expect_bad_prior(&p, "indefinite");
    /* Positive semi-definite, singular. */
    p = test_prior(0, 0, 0, 0, 1.0);
    p.cov[3][3] = 0;
    expect_bad_prior(&p, "singular");
    /* Negative diagonal. */
    p = test_prior(0, 0, 0, 0, 1.0);
    p.cov[0][0] = -1;
    expect_bad_prior(&p, "negative diagonal");
    /* Non-finite mean. */
    p = test_prior(0, (double)NAN, 0, 0, 1.0);
    expect_bad_prior(&p, "NaN mean");
    p = test_prior(0, 0, 0, (double)INFINITY, 1.0);
    expect_bad_prior(&p, "Inf mean");
    /* Non-finite covariance entries, symmetric. */
    p = test_prior(0, 0, 0, 0, 1.0);
    p.cov[2][3] = p.cov[3][2] = NAN_R;
    expect_bad_prior(&p, "NaN cov");
    p = test_prior(0, 0, 0, 0, 1.0);
    p.cov[1][1] = INF_R;
    expect_bad_prior(&p, "Inf cov");
}

static void test_init_prior_copied(void **unused)
{
    icoac_config_t cfg = test_default_config();
    icoac_state_t state;
    icoac_prior_t p = test_prior(0.1, -0.2, 0.3, -0.4, 2.0);
    icoac_prior_t post;
    int i, j;
    (void)unused;
    p.cov[0][3] = p.cov[3][0] = (icoac_real_t)0.5;
    assert_int_equal(icoac_prior_check(&p), ICOAC_OK);
    assert_int_equal(icoac_init(&cfg, &state, &p, 3u), ICOAC_OK);
    assert_int_equal(icoac_get_posterior(&state, &post), ICOAC_OK);
    assert_memory_equal(post.mean, p.mean, sizeof p.mean);
    assert_memory_equal(post.cov, p.cov, sizeof p.cov);
    /* NULL prior: mean 0, covariance I. */
    assert_int_equal(icoac_init(&cfg, &state, NULL, 3u), ICOAC_OK);
    assert_int_equal(icoac_get_posterior(&state, &post), ICOAC_OK);
    for (i = 0; i < ICOAC_N_INPUTS; ++i) {
        assert_true(post.mean[i] == 0);
        for (j = 0; j < ICOAC_N_INPUTS; ++j) {
            assert_true(post.cov[i][j] == (i == j ? 1 : 0));
        }
    }
    for (i = 0; i < ICOAC_CRITIC_UNITS; ++i) {
        assert_true(state.v[i] == 0);
    }
    assert_true(state.penalty_prev == 0);
}

static void test_null_pointers(void **unused)
{
    icoac_config_t cfg = test_default_config();
    icoac_state_t state;
    icoac_input_t in = test_input(0, 0, 0, 0, 0);
    icoac_output_t out;
    icoac_prior_t post;
    (void)unused;
    assert_int_equal(icoac_config_check(NULL), ICOAC_ERR_NULL);
    assert_int_equal(icoac_prior_check(NULL), ICOAC_ERR_NULL);
    assert_int_equal(icoac_init(NULL, &state, NULL, 0u), ICOAC_ERR_NULL);
    assert_int_equal(icoac_init(&cfg, NULL, NULL, 0u), ICOAC_ERR_NULL);
    assert_int_equal(icoac_init(&cfg, &state, NULL, 0u), ICOAC_OK);
    assert_int_equal(icoac_reset(NULL, &state), ICOAC_ERR_NULL);
    assert_int_equal(icoac_reset(&cfg, NULL), ICOAC_ERR_NULL);
    memset(&out, 0x7F, sizeof out);
    assert_int_equal(icoac_step(NULL, &state, &in, &out), ICOAC_ERR_NULL);
    assert_int_equal(out.status, ICOAC_ERR_NULL);
    assert_true(out.force == 0);
    memset(&out, 0x7F, sizeof out);
    assert_int_equal(icoac_step(&cfg, NULL, &in, &out), ICOAC_ERR_NULL);
    assert_int_equal(out.status, ICOAC_ERR_NULL);
    assert_true(out.force == 0);
    memset(&out, 0x7F, sizeof out);
    assert_int_equal(icoac_step(&cfg, &state, NULL, &out), ICOAC_ERR_NULL);
    assert_int_equal(out.status, ICOAC_ERR_NULL);
    assert_true(out.force == 0);
    assert_int_equal(icoac_step(&cfg, &state, &in, NULL), ICOAC_ERR_NULL);
    assert_int_equal(icoac_get_posterior(NULL, &post), ICOAC_ERR_NULL);
    assert_int_equal(icoac_get_posterior(&state, NULL), ICOAC_ERR_NULL);
    /* None of the rejected calls counted a tick. */
    assert_int_equal(state.ticks, 0);
}

static void test_not_initialised(void **unused)
{
    icoac_config_t cfg = test_default_config();
    icoac_state_t state;
    icoac_state_t copy;
    icoac_input_t in = test_input(0.1, 0, 0.05, 0, 0);
    icoac_output_t out;
    icoac_prior_t post;
    (void)unused;
    memset(&state, 0, sizeof state);
    memset(&out, 0x7F, sizeof out);
    copy = state;
    assert_int_equal(icoac_step(&cfg, &state, &in, &out), ICOAC_ERR_NOT_INITIALISED);
    assert_int_equal(out.status, ICOAC_ERR_NOT_INITIALISED);
    assert_true(out.force == 0);
    assert_int_equal(icoac_reset(&cfg, &state), ICOAC_ERR_NOT_INITIALISED);
    assert_int_equal(icoac_get_posterior(&state, &post), ICOAC_ERR_NOT_INITIALISED);
    assert_memory_equal(&state, &copy, sizeof state);
    /* Garbage is not mistaken for an initialised state. */
    memset(&state, 0xA5, sizeof state);
    assert_int_equal(icoac_step(&cfg, &state, &in, &out), ICOAC_ERR_NOT_INITIALISED);
}

static void test_status_strings(void **unused)
{
    static const icoac_status_t all[] = {
        ICOAC_OK, ICOAC_ERR_NULL, ICOAC_ERR_NOT_INITIALISED, ICOAC_ERR_NONFINITE_INPUT, ICOAC_ERR_NUMERIC,
        ICOAC_ERR_BAD_MODE, ICOAC_ERR_BAD_SCALE, ICOAC_ERR_BAD_GAIN, ICOAC_ERR_BAD_ZONE,
        ICOAC_ERR_BAD_ICO_RATE, ICOAC_ERR_BAD_CRITIC, ICOAC_ERR_BAD_ACTOR, ICOAC_ERR_BAD_PRIOR};
    const size_t n = sizeof all / sizeof all[0];
    const char *unknown;
    size_t i, j;
    int raw;
    (void)unused;
    unknown = icoac_status_str((icoac_status_t)999);
    assert_non_null(unknown);
    for (i = 0; i < n; ++i) {
        const char *s = icoac_status_str(all[i]);
        assert_non_null(s);
        assert_true(strlen(s) > 0);
        /* Named statuses have their own text, distinct from each other and from "unknown". */
        assert_string_not_equal(s, unknown);
        for (j = 0; j < i; ++j) {
            assert_string_not_equal(s, icoac_status_str(all[j]));
        }
    }
    for (raw = -5; raw < 200; ++raw) {
        assert_non_null(icoac_status_str((icoac_status_t)raw));
    }
}

static void test_sizeof_functions(void **unused)
{
    (void)unused;
    assert_int_equal(icoac_abi_version(), ICOAC_ABI_VERSION);
    assert_int_equal(icoac_sizeof_real(), sizeof(icoac_real_t));
    assert_int_equal(icoac_sizeof_real(), REAL_IS_FLOAT ? 4 : 8);
    assert_int_equal(icoac_sizeof_config(), sizeof(icoac_config_t));
    assert_int_equal(icoac_sizeof_state(), sizeof(icoac_state_t));
    assert_int_equal(icoac_sizeof_input(), sizeof(icoac_input_t));
    assert_int_equal(icoac_sizeof_output(), sizeof(icoac_output_t));
    assert_int_equal(icoac_sizeof_prior(), sizeof(icoac_prior_t));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_defaults_match_spec),
        cmocka_unit_test(test_bad_configs_rejected_state_untouched),
        cmocka_unit_test(test_bad_priors),
        cmocka_unit_test(test_init_prior_copied),
        cmocka_unit_test(test_null_pointers),
        cmocka_unit_test(test_not_initialised),
        cmocka_unit_test(test_status_strings),
        cmocka_unit_test(test_sizeof_functions),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
