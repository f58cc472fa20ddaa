# Peer measurement for bench_bbm: Yade's bonded-particle model JCFpm (Scholtès &
# Donzé), 8,352 spheres (radius 0.02 m, 0.6 x 0.6 x 1.2 m) bonded into a block and compressed, stepped for a
# fixed number of steps; prints contact-updates per second (real interactions x
# steps / wall seconds), the figure bbm's bench_bbm reports for its loop.
# Run by bench/yade_peer.sh: yade -j THREADS -n -x bench/yade_jcfpm.py
import time
from yade import pack

young, poisson = 20e9, 0.2
O.materials.append(JCFpmMat(young=young, poisson=poisson, frictionAngle=radians(25), density=2700,
                            tensileStrength=3e6, cohesion=9.5e6, label='rock'))
O.bodies.append(pack.regularHexa(pack.inAlignedBox((0, 0, 0), (0.6, 0.6, 1.2)), radius=0.02, gap=0,
                                 material='rock'))
particles = len(O.bodies)
top = [b for b in O.bodies if b.state.pos[2] > 1.2 - 0.03]
bottom = [b for b in O.bodies if b.state.pos[2] < 0.03]
for b in top + bottom:
    b.state.blockedDOFs = 'xyzXYZ'
for b in top:
    b.state.vel = Vector3(0, 0, -0.01)

factor = 1.2  # bonds between near neighbours, as JCFpm examples do
O.engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Sphere_Aabb(aabbEnlargeFactor=factor, label='aabb')]),
    InteractionLoop([Ig2_Sphere_Sphere_ScGeom(interactionDetectionFactor=factor, label='geom')],
                    [Ip2_JCFpmMat_JCFpmMat_JCFpmPhys(cohesiveTresholdIteration=1)],
                    [Law2_ScGeom_JCFpmPhys_JointedCohesiveFrictionalPM()]),
    NewtonIntegrator(damping=0.4),
]
O.dt = 0.5 * PWaveTimeStep()
O.step()  # the bonds form at the first step
aabb.aabbEnlargeFactor = geom.interactionDetectionFactor = -1
O.run(50, True)  # warm-up
steps = 2000
t0 = time.time()
O.run(steps, True)
seconds = time.time() - t0
contacts = O.interactions.countReal()
print('yade-jcfpm particles %d contacts %d threads %d steps %d seconds %.3f contact_updates_per_second %.4g' %
      (particles, contacts, O.numThreads, steps, seconds, contacts * steps / seconds))
