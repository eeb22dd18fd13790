"""Not a benchmark: an independent lumped-mass computation of the nominal FAST model's
modes, against fastcal.modes (issue 40's acceptance: the 10 lowest frequencies at six
focal-law poses, zenith 0, 20 and 40 deg, within 0.3%; docs/model.md, "Vibrations").

Its own discretisation and its own equilibrium: the chains of N bars with lumped masses
and the rigid cabin, started from parabolas, brought to the minimum of their total
potential energy by Newton (a Levenberg shift where the start is indefinite, a line
search); the Hessian by central differences of the gradient; scipy's eigh. From fastcal
only the pose (the start) and the unstretched lengths of the exact statics, and its
focal law.

Run: build/python/python3 bench/modes_independent_check.py [N=16]   (~80 s at N = 16)"""
import sys
import numpy as np
import scipy.linalg as sl
import fastcal

N = int(sys.argv[1]) if len(sys.argv) > 1 else 16
G = -9.8
m_cab = 30000.0
r_e = np.array([0.0, 0.0, 0.5])
I_c = np.diag([3.5e5, 3.5e5, 5.0e5])
EA = 2.4656e7
RHO = 11.718
ra, rb, H = 7.5, 300.0, 270.0
towers = np.array([[rb*np.cos(np.pi*i/3), rb*np.sin(np.pi*i/3), H] for i in range(6)])
anch = np.array([[ra*np.cos(np.pi/6 + 2*np.pi*j/3), ra*np.sin(np.pi/6 + 2*np.pi*j/3), 0.0] for j in range(3)])
anchors = np.array([anch[i//2] for i in range(6)])

def rot(v):
    th = np.linalg.norm(v)
    K = np.array([[0,-v[2],v[1]],[v[2],0,-v[0]],[-v[1],v[0],0]])
    if th < 1e-12: return np.eye(3) + K
    return np.eye(3) + np.sin(th)/th*K + (1-np.cos(th))/th**2*K@K

def run(position, quat):
    sol = fastcal.solve(np.array(position), quat=quat)
    s0 = sol.s0_m
    w,x,y,z = quat
    R0 = np.array([[1-2*(y*y+z*z), 2*(x*y-w*z), 2*(x*z+w*y)],
                   [2*(x*y+w*z), 1-2*(x*x+z*z), 2*(y*z-w*x)],
                   [2*(x*z-w*y), 2*(y*z+w*x), 1-2*(x*x+y*y)]])
    p0 = np.array(position, dtype=float)
    l0 = s0 / N
    mnode = RHO * l0
    nint = N - 1
    # Start: nodes on straight chords sagged a little (not fastcal's catenary).
    nodes0 = []
    for i in range(6):
        a = p0 + R0 @ anchors[i]
        t = np.linspace(0, 1, N+1)[1:-1]
        pts = a[None,:] + t[:,None]*(towers[i]-a)[None,:]
        L = np.linalg.norm((towers[i]-a)[:2])
        fl = 1e3*np.linalg.norm(sol.force_kN[i][:2])
        pts[:,2] -= RHO*9.8*L*L/(8*fl)*4*t*(1-t)
        nodes0.append(pts)
    nodes0 = np.array(nodes0)  # 6 x nint x 3

    def unpack(q):
        u, th = q[:3], q[3:6]
        X = q[6:].reshape(6, nint, 3)
        return u, th, X

    def energy_terms(u, th, X):
        R = rot(th) @ R0
        A = p0 + u + (R @ anchors.T).T  # 6x3
        full = np.concatenate([A[:,None,:], X, towers[:,None,:]], axis=1)  # 6 x N+1 x 3
        d = full[:,1:,:] - full[:,:-1,:]
        l = np.linalg.norm(d, axis=2)
        Ve = 0.5*EA/l0[:,None]*(l - l0[:,None])**2
        # gravity: interior nodes full mass, anchor node half (moves with the cabin), tower half fixed
        Vg = -G*(mnode[:,None]*X[:,:,2]).sum() - G*(0.5*mnode*A[:,2]).sum()
        c = p0 + u + R @ r_e
        Vc = -G*m_cab*c[2]
        return Ve.sum() + Vg + Vc, full, d, l, A, R

    def V(q):
        u, th, X = unpack(q)
        return energy_terms(u, th, X)[0]

    def grad(q):
        u, th, X = unpack(q)
        _, full, d, l, A, R = energy_terms(u, th, X)
        f = (EA/l0[:,None]*(l - l0[:,None]))[:,:,None] * d / l[:,:,None]  # segment force along d
        gnode = np.zeros_like(full)
        gnode[:,1:,:] += f
        gnode[:,:-1,:] -= f
        gX = gnode[:,1:-1,:].copy()
        gX[:,:,2] += -G*mnode[:,None]
        gA = gnode[:,0,:].copy()
        gA[:,2] += -G*0.5*mnode
        gu = gA.sum(axis=0) + np.array([0,0,-G*m_cab])
        # theta by central differences of the energy (first derivatives: accurate)
        gth = np.zeros(3)
        h = 1e-6
        for k in range(3):
            e = np.zeros(3); e[k] = h
            qp = q.copy(); qp[3:6] += e
            qm = q.copy(); qm[3:6] -= e
            gth[k] = (V(qp) - V(qm))/(2*h)
        return np.concatenate([gu, gth, gX.ravel()])

    def hessian(q):
        n = q.size
        Hm = np.zeros((n,n))
        for k in range(n):
            h = 1e-4 if k >= 3 else 1e-4
            e = np.zeros(n); e[k] = h
            Hm[:,k] = (grad(q+e) - grad(q-e))/(2*h)
        return 0.5*(Hm+Hm.T)

    q = np.concatenate([np.zeros(6), nodes0.ravel()])
    for it in range(80):
        g = grad(q)
        Hm = hessian(q)
        # Newton on a positive definite Hessian (Levenberg's shift where the start makes it
        # indefinite: a slack chain), with a backtracking line search on the energy.
        mu = 0.0
        while True:
            try:
                L = np.linalg.cholesky(Hm + mu*np.diag(np.abs(np.diag(Hm))))
                break
            except np.linalg.LinAlgError:
                mu = 1e-3 if mu == 0.0 else 10*mu
        step = sl.cho_solve((L, True), -g)
        scale = 1.0
        v0 = V(q)
        while V(q + scale*step) > v0 + 1e-4*scale*(g @ step) and scale > 1e-8:
            scale *= 0.5
        q = q + scale*step
        if mu == 0.0 and np.abs(step).max() < 1e-9: break
    u, th, X = unpack(q)
    R = rot(th) @ R0
    Hm = hessian(q)  # at the equilibrium (gradient ~0: the chart does not matter)
    n = q.size
    M = np.zeros((n,n))
    e = R @ r_e
    E = np.array([[0,-e[2],e[1]],[e[2],0,-e[0]],[-e[1],e[0],0]])
    IG = R @ I_c @ R.T
    M[:3,:3] = m_cab*np.eye(3)
    M[:3,3:6] = -m_cab*E
    M[3:6,:3] = m_cab*E
    M[3:6,3:6] = IG - m_cab*E@E
    for i in range(6):
        r = R @ anchors[i]
        Rx = np.array([[0,-r[2],r[1]],[r[2],0,-r[0]],[-r[1],r[0],0]])
        T = np.hstack([np.eye(3), -Rx])
        M[:6,:6] += 0.5*mnode[i]*T.T@T
    M[6:,6:] = np.diag(np.repeat(mnode, nint*3))
    # The Hessian's rotation chart is exp(theta) R0 at theta = th (~1e-4 rad), the mass
    # matrix's small rotations about the world axes at R: the same to first order in th.
    lam = sl.eigh(Hm, M, eigvals_only=True)
    return np.sqrt(np.maximum(lam[:20], 0))/(2*np.pi), np.abs(g).max(), it, np.linalg.norm(u), np.linalg.norm(th)

POSES = []
for zen, az in [(0, 0), (20, 0), (20, 30), (40, 0), (40, 30), (40, 75)]:
    z, a = np.radians(zen), np.radians(az)
    POSES.append((160*np.sin(z)*np.cos(a), 160*np.sin(z)*np.sin(a), 300 - 160*np.cos(z)))
for position in POSES:
    quat = fastcal.focal_attitude(np.array(position))
    f_ind, gmax, it, du, dth = run(position, quat)
    f_fc = fastcal.modes(position, quat=quat, segments=N, count=20).frequency_hz
    rel = np.abs(f_fc[:10]/f_ind[:10] - 1)
    print(f"pose ({position[0]:.2f}, {position[1]:.2f}, {position[2]:.2f}): Newton {it} it, |grad| {gmax:.2e}, moved {du*1e3:.2f} mm, {dth:.2e} rad; "
          f"lowest 10: max rel diff {rel.max():.2e}")
    print("  indep ", " ".join(f"{x:.5f}" for x in f_ind[:10]))
    print("  fastcal", " ".join(f"{x:.5f}" for x in f_fc[:10]))
