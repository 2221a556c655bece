import gym
import numpy as np
import random
def random_blackjack(n):
    e=gym.make('Blackjack-v0');w=0
    for i in range(n):
        e.reset();d=False
        while not d:o,r,d,_=e.step(random.randint(0,1))
        w+=r>0
    return w/n
def blackjack(n=11):
    e=gym.make('Blackjack-v0');w=0
    for i in range(10000):
        o=e.reset();d=False
        while not d:o,r,d,_=e.step(o[0]<=n)
        w+=r==1
    return w/10000
def cartpole():
    e=gym.make('CartPole-v0');o=e.reset();d=False;c=0
    while not d:o,r,d,_=e.step(int(o[3]>0));c+=1
    return c
def car():
    e=gym.make('MountainCar-v0');o=e.reset();d=False;c=0
    while not d:o,r,d,_=e.step(0 if o[1]<0 else 2);c+=1
    return c
def taxi(q_table):
    e=gym.make('Taxi-v3');a=b=0
    for i in range(10000):
        e.reset();d=False
        while not d:s,r,d,_=e.step(e.action_space.sample());a+=r
    for i in range(10000):
        s=e.reset();d=False
        while not d:s,r,d,_=e.step(np.argmax(q_table[s]));b+=r
    return a/10000,b/10000
